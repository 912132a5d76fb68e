"""Float64 kernels and size thresholds of the ray engine.

Row-wise vector helpers, the float64 Moller-Trumbore triangle test, the analytic true-surface
intersectors of spheres, cylinders, capsules and cones (vectorised, and their bit-identical scalar
twins for a few rays), and the per-cast parameter normalisation.  Pure numpy/math: no Embree.
"""

from __future__ import annotations

import math

import numpy as np

_F32 = np.float32
_INF = np.inf
_MAX_LOOPS = 32          # continuation iterations per tier and cast
_BARY_TOL = 1e-9         # barycentric tolerance of float64 triangle tests (relative)
_LEAK_OFFSET_ULPS = 4.0  # perpendicular offset of the repair copy, in float32 ulps of the tier
_SPHERE, _CYLINDER, _CAPSULE, _CONE = 1, 2, 3, 4   # a cone: numpy only (packets.c knows the first three)
# two generic (non axis-aligned) directions used to build a perpendicular for the repair copy
_AUX1 = np.array([0.5773, 0.2113, 0.7887]) / np.linalg.norm([0.5773, 0.2113, 0.7887])
_AUX2 = np.array([-0.3, 0.9, 0.1]) / np.linalg.norm([-0.3, 0.9, 0.1])
# Size thresholds.  A numpy call costs ~1-3 us whatever its size up to a few thousand elements,
# so small batches (a distance sensor's 3 rays) take plain-float shortcuts and large ones stay
# vectorised; every shortcut computes the same answer (tests/test_raycast_paths.py).
_SMALL = 64              # per-ray arrays up to this size: Python list tricks (uniformity, max |x|)
_TINY = 12               # (ray, mover) / (ray, curved shape) tables up to this size: Python floats
_SCALAR = 8              # (ray, curved shape) pairs intersected analytically in Python floats
_FEW_MOVERS = 4          # up to this many movers, or ...
_DENSE_PAIRS = 16384     # ... (rays x movers) up to this size: one dense broad-phase test, else a grid
_PRUNE = 64              # from this many (ray, mover) pairs of one tier, a bound test prunes them
_MIXED = 1024            # up to this many (ray, curved shape) pairs of several kinds: one pass for all kinds
_MATMUL_ROWS = 32768     # row block of (n,3) @ (3,3) products (see _mat)
_CHUNK = 1 << 16         # rays per pass of a large cast (RayEngine.cast): bounds its temporaries


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of (n,3) arrays (column sums beat einsum here)."""
    p = a * b
    return p[:, 0] + p[:, 1] + p[:, 2]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(a.shape if a.shape == b.shape else np.broadcast_shapes(a.shape, b.shape))   # (broadcast_shapes: ~5 us)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _take(x, idx):
    """Index a per-ray parameter that may be a scalar."""
    return x[idx] if isinstance(x, np.ndarray) else x


def _rows(x: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """x[idx] for a sorted subset idx of range(len(x)): the array itself when idx is everything
    (np.take is also markedly faster than fancy indexing for (n,3) arrays)."""
    return x if len(idx) == len(x) else x.take(idx, axis=0)


def _minus(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """x - v for (n,3) x and (3,) v, column by column for large n (numpy broadcasts a length-3
    inner axis slowly; for a few rows one call is cheaper)."""
    if len(x) <= _SMALL:
        return x - v
    out = np.empty(x.shape)
    for k in range(3):
        np.subtract(x[:, k], v[k], out=out[:, k])
    return out


def _one_row(row: np.ndarray, m: int) -> np.ndarray:
    """A read-only (m, 3) view repeating the one (1, 3) row (``np.broadcast_to``'s array, at a tenth
    of its cost)."""
    row = np.ascontiguousarray(row)
    v = np.ndarray((m, 3), row.dtype, row, 0, (0, row.itemsize))
    v.flags.writeable = False
    return v


def _start32(o: np.ndarray, d: np.ndarray, s) -> np.ndarray:
    """float32(o + s d) for (m,3) origins (possibly one broadcast row) and directions and a scalar
    or per-row s: the float64 sum rounded once, by columns for large m (broadcasting over a
    length-3 axis into a float32 output is ~4x slower; the same values)."""
    m = len(d)
    if m <= _SMALL:
        out = np.empty(d.shape, dtype=_F32)
        np.add(o, d * (s[:, None] if isinstance(s, np.ndarray) else s), out=out, casting="same_kind")
        return out
    out = np.empty((m, 3), dtype=_F32)
    t = np.empty(m)
    one = o.strides[0] == 0
    for k in range(3):
        np.multiply(d[:, k], s, out=t)
        t += o[0, k] if one else o[:, k]
        out[:, k] = t
    return out


def _mat(x: np.ndarray, M: np.ndarray) -> np.ndarray:
    """x @ M for (n, k) x and a small (k, j) M, in blocks of rows: OpenBLAS multi-threads larger
    products, which made a (131072, 3) @ (3, 3) product ~100x slower on a busy 2-core machine."""
    n = len(x)
    if n <= _MATMUL_ROWS:
        return x @ M
    out = np.empty((n,) + M.shape[1:])
    for a in range(0, n, _MATMUL_ROWS):
        np.matmul(x[a:a + _MATMUL_ROWS], M, out=out[a:a + _MATMUL_ROWS])
    return out


def _to_frame(x: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``x @ R`` for (n,3) rows and one rotation (world to a shape's or body's frame), each row
    summed as (x0 R[0] + x1 R[1]) + x2 R[2]: the bits of ``einsum("nij,ni->nj")`` (rows with
    several rotations) and of the scalar twins, whatever n. A BLAS product rounds differently
    (fused multiply-adds), so a ray's answer would depend on whether the other rays of its batch
    met the same shape; in blocks of rows for large n (contiguous columns, no BLAS threads)."""
    n = len(x)
    if n <= _SMALL:
        return (x[:, 0:1] * R[0] + x[:, 1:2] * R[1]) + x[:, 2:3] * R[2]
    out = np.empty((n, 3))
    tmp = np.empty(min(n, _MATMUL_ROWS))
    for a in range(0, n, _MATMUL_ROWS):
        b = min(n, a + _MATMUL_ROWS)
        t, x0, x1, x2 = tmp[:b - a], x[a:b, 0], x[a:b, 1], x[a:b, 2]
        for j in range(3):
            col = out[a:b, j]
            np.multiply(x0, R[0, j], out=col)
            np.multiply(x1, R[1, j], out=t)
            col += t
            np.multiply(x2, R[2, j], out=t)
            col += t
    return out


def _from_frame(x: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``x @ R.T`` (a shape's or body's frame back to the world), each row summed as
    (x0 R[:,0] + x2 R[:,2]) + x1 R[:,1]: the bits of ``einsum("nij,nj->ni")``, whatever n."""
    return (x[:, 0:1] * R[:, 0] + x[:, 2:3] * R[:, 2]) + x[:, 1:2] * R[:, 1]


def _ulp32(x: float) -> float:
    return float(np.spacing(_F32(max(abs(x), 1e-30))))


def _moller_trumbore(o, d, v0, e1, e2, tol=_BARY_TOL):
    """Float64 ray/triangle test: (inside within barycentric tol, t)."""
    p = _cross(d, e2)
    inv = 1.0 / _dot(e1, p)
    s = o - v0
    u = _dot(s, p) * inv
    q = _cross(s, e1)
    v = _dot(d, q) * inv
    t = _dot(e2, q) * inv
    ok = np.isfinite(t) & (u >= -tol) & (v >= -tol) & (u + v <= 1.0 + tol)
    return ok, t


# The analytic intersectors below write candidate distances into the columns of one (m, k) table
# and pick the nearest in [lo, hi]: a handful of numpy calls per shape kind, whatever m is (a
# distance sensor casts 3 rays; per-call overhead dominates).  Floating-point warnings are
# silenced once per cast (see RayEngine.cast).


def _root_pair(ts, k, a, b, c, disc):
    """The roots q / a and c / q of a t^2 + 2 b t + c = 0 (q = -(b + sign(b) sqrt(disc)), the
    cancellation-free pair) into ts[:, k] and ts[:, k+1], unfiltered; returns those two columns."""
    s = np.sqrt(np.maximum(disc, 0.0))
    q = -(b + np.copysign(s, b))
    t1, t2 = ts[:, k], ts[:, k + 1]
    np.divide(q, a, out=t1)
    np.divide(c, q, out=t2)
    np.copyto(t2, t1, where=q == 0.0)
    return t1, t2


def _roots_into(ts, k, a, b, c, disc):
    """Both roots of a t^2 + 2 b t + c = 0 into ts[:, k] and ts[:, k+1], given disc = b^2 - a c
    (computed stably by the caller); +inf where there is no real root."""
    t1, _ = _root_pair(ts, k, a, b, c, disc)
    bad = (disc < 0.0) | ~np.isfinite(t1)
    np.copyto(ts[:, k:k + 2], _INF, where=bad[:, None])


def _sphere_roots_into(ts, k, p, d, r):
    a = _dot(d, d)
    b = _dot(p, d)
    c = _dot(p, p) - r * r
    x = _cross(p, d)
    _roots_into(ts, k, a, b, c, a * r * r - _dot(x, x))  # |p x d|^2 form: no cancellation far away


_CONE_DISC_TOL = (16.0 * 2.0 ** -52) ** 2    # of |p'|² (1 + k²): the cone's discriminant's rounding


def _cone_roots_into(ts, k, a, b, c, disc):
    """``_roots_into`` for a cone's side, whose leading coefficient ``a`` is 0 for a ray parallel to
    a generating line: then the one root ``c / q`` is kept (a cylinder's ``a`` = 0 has none)."""
    t1, t2 = _root_pair(ts, k, a, b, c, disc)
    np.copyto(t1, _INF, where=~np.isfinite(t1))
    np.copyto(t2, _INF, where=~np.isfinite(t2))
    np.copyto(ts[:, k:k + 2], _INF, where=(disc < 0.0)[:, None])


def _cone_local(p, d, r, h, lo, hi, normals=True):
    """``_analytic_local`` of a cone (Webots' Cone: axis z, apex at z = +h, base disc of radius
    ``r`` at z = −h; ``h`` half the height): the side ``x² + y² = k²(h − z)²`` (k = r / 2h) within
    −h ≤ z ≤ h (columns 0, 1), the base (column 2). The normal on the side is the gradient
    ``(x, y, k²(h − z))``, +z at the apex itself; −z on the base.

    The discriminant is ``k²(cx² + cy²) − cz²`` with ``c = p' × d'`` (p' the origin from the apex,
    z flipped, d' likewise): the same quantity as ``b² − ac`` for this quadratic form, without its
    cancellation (a ray through the apex has a double root: ``b² − ac`` would lose half the digits
    of t there, and miss half the time). A discriminant within rounding of 0 below it counts as 0."""
    m = len(p)
    col = (lambda x: x[:, None]) if isinstance(h, np.ndarray) else (lambda x: x)  # noqa: E731
    tol = 1e-12 * (r + h)
    k = r / (h + h)
    k2 = k * k
    px, py, pz, dx, dy, dz = p[:, 0], p[:, 1], p[:, 2], d[:, 0], d[:, 1], d[:, 2]
    w = h - pz
    ts = np.empty((m, 3))
    a = dx * dx + dy * dy - k2 * (dz * dz)
    b = px * dx + py * dy + k2 * (w * dz)
    c = px * px + py * py - k2 * (w * w)
    cx, cy, cz = -(py * dz) - w * dy, w * dx + px * dz, px * dy - py * dx
    disc = k2 * (cx * cx + cy * cy) - cz * cz
    near = (disc < 0.0) & (disc >= -_CONE_DISC_TOL * (px * px + py * py + w * w) * (1.0 + k2))
    np.copyto(disc, 0.0, where=near)
    _cone_roots_into(ts, 0, a, b, c, disc)
    side = ts[:, 0:2]
    z = p[:, 2:3] + side * d[:, 2:3]
    np.copyto(side, _INF, where=~((z <= col(h + tol)) & (z >= col(-h - tol))))
    base = ts[:, 2]
    np.divide(-h - pz, dz, out=base)
    bx, by = px + base * dx, py + base * dy
    np.copyto(base, _INF, where=~(np.isfinite(base) & (bx * bx + by * by <= r * r + tol * r)))
    np.copyto(ts, _INF, where=~((ts >= lo[:, None]) & (ts <= hi[:, None])))
    if not normals:
        return ts.min(axis=1), None
    j = ts.argmin(axis=1)       # first of equal candidates, in column order
    t = ts[np.arange(m), j]
    hit = t < _INF
    t0 = t.copy()
    np.copyto(t0, 0.0, where=~hit)
    n = p + t0[:, None] * d            # hit point
    n[:, 2] = np.where(j == 2, -1.0, k2 * (h - n[:, 2]))
    n[:, 0:2] *= (j < 2)[:, None]
    norm = np.sqrt(_dot(n, n))
    apex = norm == 0.0
    n[apex] = (0.0, 0.0, 1.0)
    norm[apex] = 1.0
    n /= norm[:, None]
    np.copyto(n, 0.0, where=~hit[:, None])
    return t, n


def _analytic_local(code, p, d, r, h, lo, hi, normals=True):
    """Nearest true-surface hit with lo <= t <= hi, shape-local frame.  ``r`` radius, ``h`` half
    height (cylinder, cone) or half length of the straight part (capsule), scalars or per-ray
    arrays; ``lo``, ``hi`` per-ray arrays.  Returns (t, unit normal), +inf / zeros where no hit
    (normal None without ``normals``: the same t)."""
    if code == _CONE:
        return _cone_local(p, d, r, h, lo, hi, normals)
    m = len(p)
    col = (lambda x: x[:, None]) if isinstance(h, np.ndarray) else (lambda x: x)  # noqa: E731
    tol = 1e-12 * (r + h)
    pz, dz = p[:, 2:3], d[:, 2:3]
    if code == _SPHERE:
        ts = np.empty((m, 2))
        _sphere_roots_into(ts, 0, p, d, r)
    else:
        # columns 0, 1: the side (infinite cylinder x^2 + y^2 = r^2) within the straight part
        ts = np.empty((m, 4 if code == _CYLINDER else 6))
        px, py, dx, dy = p[:, 0], p[:, 1], d[:, 0], d[:, 1]
        a = dx * dx + dy * dy
        x = px * dy - py * dx
        _roots_into(ts, 0, a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x)
        side = ts[:, 0:2]
        np.copyto(side, _INF, where=~(np.abs(pz + side * dz) <= col(h + tol)))
        if code == _CYLINDER:  # columns 2, 3: caps z = +h, z = -h, within the disc
            caps = ts[:, 2:4]
            np.divide(col(h) * np.array([1.0, -1.0]) - pz, dz, out=caps)
            cx, cy = p[:, 0:1] + caps * d[:, 0:1], p[:, 1:2] + caps * d[:, 1:2]
            np.copyto(caps, _INF, where=~(np.isfinite(caps) & (cx * cx + cy * cy <= col(r * r + tol * r))))
        else:  # columns 2, 3 / 4, 5: hemispheres centred at z = +h / -h, beyond their centre
            for k, sign in ((2, 1.0), (4, -1.0)):
                pc = p.copy()
                pc[:, 2] -= sign * h
                _sphere_roots_into(ts, k, pc, d, r)
                cap = ts[:, k:k + 2]
                np.copyto(cap, _INF, where=~(sign * (pz + cap * dz) >= col(h - tol)))
    np.copyto(ts, _INF, where=~((ts >= lo[:, None]) & (ts <= hi[:, None])))
    if not normals:
        return ts.min(axis=1), None
    if m <= 256:
        k = ts.argmin(axis=1)   # first of equal candidates, in column order
        t = ts[np.arange(m), k]
    else:                       # the same by columns (argmin over a short axis is slow for many rows)
        t = ts[:, 0].copy()
        k = np.zeros(m, dtype=np.int64)
        for j in range(1, ts.shape[1]):
            better = ts[:, j] < t
            k[better] = j
            np.minimum(t, ts[:, j], out=t)
    hit = t < _INF
    t0 = t.copy()
    np.copyto(t0, 0.0, where=~hit)
    n = p + t0[:, None] * d            # hit point
    if code == _CYLINDER:              # side: radial; caps: +-z
        n[:, 0:2] *= (k < 2)[:, None]
        n[:, 2] = (k == 2).astype(np.float64) - (k == 3)
    elif code == _CAPSULE:             # side: radial; hemispheres: from their centre
        n[:, 2] -= np.where(k < 2, n[:, 2], np.where(k < 4, h, -h))
    n /= np.sqrt(_dot(n, n))[:, None]
    np.copyto(n, 0.0, where=~hit[:, None])
    return t, n


def _analytic_mixed(codes, p, d, r, h, lo, hi, normals=True):
    """``_analytic_local`` for rows of different shape kinds (``codes``, ``r``, ``h`` per row) in one
    pass: every row gets the eight candidate columns -- the side (0, 1), a cylinder's caps (2, 3),
    a capsule's hemispheres (4, 5 at z = +h; 6, 7 at z = -h), a sphere being the capsule with
    h = 0 -- and the columns its kind does not have are masked out. Each row's candidates, their
    order and the arithmetic of its normal are those of its kind in ``_analytic_local``, so the
    same hits (for a few rows, one pass of ~50 numpy calls instead of ~35 per kind present)."""
    m = len(p)
    sphere, cyl = codes == _SPHERE, codes == _CYLINDER
    tol = 1e-12 * (r + h)
    hc, tc, rc = h[:, None], tol[:, None], r[:, None]
    pz, dz = p[:, 2:3], d[:, 2:3]
    ts = np.empty((m, 8))
    px, py, dx, dy = p[:, 0], p[:, 1], d[:, 0], d[:, 1]
    a = dx * dx + dy * dy
    x = px * dy - py * dx
    _roots_into(ts, 0, a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x)
    side = ts[:, 0:2]
    np.copyto(side, _INF, where=~(np.abs(pz + side * dz) <= hc + tc) | sphere[:, None])
    caps = ts[:, 2:4]
    np.divide(hc * np.array([1.0, -1.0]) - pz, dz, out=caps)
    cx, cy = p[:, 0:1] + caps * d[:, 0:1], p[:, 1:2] + caps * d[:, 1:2]
    np.copyto(caps, _INF, where=~(np.isfinite(caps) & (cx * cx + cy * cy <= rc * rc + tc * rc)) | ~cyl[:, None])
    for k, sign in ((4, 1.0), (6, -1.0)):
        pc = p.copy()
        pc[:, 2] -= sign * h
        _sphere_roots_into(ts, k, pc, d, r)
        cap = ts[:, k:k + 2]
        np.copyto(cap, _INF, where=~(sign * (pz + cap * dz) >= hc - tc) | cyl[:, None])
    np.copyto(ts, _INF, where=~((ts >= lo[:, None]) & (ts <= hi[:, None])))
    if not normals:
        return ts.min(axis=1), None
    k = ts.argmin(axis=1)   # first of equal candidates, in column order (each kind's own order)
    t = ts[np.arange(m), k]
    hit = t < _INF
    t0 = t.copy()
    np.copyto(t0, 0.0, where=~hit)
    n = p + t0[:, None] * d            # hit point
    # cylinder: side radial, caps +-z; capsule (and sphere, h = 0): hemispheres from their centre
    n[:, 0:2] *= np.where(cyl, k < 2, 1.0)[:, None]
    nz = n[:, 2]
    n[:, 2] = np.where(cyl, (k == 2).astype(np.float64) - (k == 3),
                       np.where(sphere, nz, nz - np.where(k < 2, nz, np.where(k < 6, h, -h))))
    n /= np.sqrt(_dot(n, n))[:, None]
    np.copyto(n, 0.0, where=~hit[:, None])
    return t, n


def _roots_one(a: float, b: float, c: float, disc: float) -> tuple[float, float]:
    """Scalar twin of ``_roots_into`` (same operations, so the same bits)."""
    if not disc >= 0.0 or a == 0.0:
        return _INF, _INF
    q = -(b + math.copysign(math.sqrt(disc), b))
    t1 = q / a
    if not math.isfinite(t1):
        return _INF, _INF
    return t1, (c / q if q != 0.0 else t1)


def _analytic_one(code: int, p, d, r: float, h: float, lo: float, hi: float):
    """Scalar twin of ``_analytic_local`` for ONE ray in Python floats: (t, normal tuple).  Same
    candidates in the same order, same tolerances and operation order (bit-identical results),
    for the few (ray, shape) pairs of a small batch, where numpy's per-call cost would dominate."""
    px, py, pz = p
    dx, dy, dz = d
    tol = 1e-12 * (r + h)
    if code == _CONE:
        return _cone_one(px, py, pz, dx, dy, dz, r, h, tol, lo, hi)
    cands = []
    if code == _SPHERE:
        cx, cy, cz = py * dz - pz * dy, pz * dx - px * dz, px * dy - py * dx
        a = dx * dx + dy * dy + dz * dz
        cands += _roots_one(a, px * dx + py * dy + pz * dz, px * px + py * py + pz * pz - r * r,
                            a * r * r - (cx * cx + cy * cy + cz * cz))
    else:
        a = dx * dx + dy * dy
        x = px * dy - py * dx
        for t in _roots_one(a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x):
            # no root (inf): no candidate, decided before inf * dz (0 for a ray parallel to the caps)
            cands.append(t if t < _INF and abs(pz + t * dz) <= h + tol else _INF)
        if code == _CYLINDER:
            for zc in (h * 1.0, h * -1.0):
                t = (zc - pz) / dz if dz != 0.0 else _INF
                if math.isfinite(t):
                    cx, cy = px + t * dx, py + t * dy
                    if not cx * cx + cy * cy <= r * r + tol * r:
                        t = _INF
                cands.append(_INF if not math.isfinite(t) else t)
        else:
            for sign in (1.0, -1.0):
                qz = pz - sign * h
                cx, cy, cz = py * dz - qz * dy, qz * dx - px * dz, px * dy - py * dx
                a3 = dx * dx + dy * dy + dz * dz
                for t in _roots_one(a3, px * dx + py * dy + qz * dz, px * px + py * py + qz * qz - r * r,
                                    a3 * r * r - (cx * cx + cy * cy + cz * cz)):
                    cands.append(t if t < _INF and sign * (pz + t * dz) >= h - tol else _INF)
    best, k = _nearest(cands, lo, hi)
    if k < 0:
        return _INF, (0.0, 0.0, 0.0)
    nx, ny, nz = px + best * dx, py + best * dy, pz + best * dz
    if code == _CYLINDER:
        if k >= 2:
            nx, ny, nz = 0.0, 0.0, (1.0 if k == 2 else -1.0)
        else:
            nz = 0.0
    elif code == _CAPSULE:
        nz -= nz if k < 2 else (h if k < 4 else -h)
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    return best, (nx / norm, ny / norm, nz / norm)


def _nearest(cands: list[float], lo: float, hi: float) -> tuple[float, int]:
    """(the nearest candidate in [lo, hi], its index; the first of equal ones, like argmin), or
    (inf, -1) when none is."""
    best, k = _INF, -1
    for j, t in enumerate(cands):
        if lo <= t <= hi and t < best:
            best, k = t, j
    return best, k


def _cone_one(px, py, pz, dx, dy, dz, r: float, h: float, tol: float, lo: float, hi: float):
    """Scalar twin of ``_cone_local`` (same operations, so the same bits)."""
    k = r / (h + h)
    k2 = k * k
    w = h - pz
    a = dx * dx + dy * dy - k2 * (dz * dz)
    b = px * dx + py * dy + k2 * (w * dz)
    c = px * px + py * py - k2 * (w * w)
    cx, cy, cz = -(py * dz) - w * dy, w * dx + px * dz, px * dy - py * dx
    disc = k2 * (cx * cx + cy * cy) - cz * cz
    if disc < 0.0 and disc >= -_CONE_DISC_TOL * (px * px + py * py + w * w) * (1.0 + k2):
        disc = 0.0
    cands = [_INF, _INF, _INF]
    if disc >= 0.0:
        q = -(b + math.copysign(math.sqrt(disc), b))
        t1 = q / a if a != 0.0 else math.copysign(_INF, q) if q != 0.0 else math.nan
        t2 = c / q if q != 0.0 else t1
        for j, t in enumerate((t1, t2)):
            if math.isfinite(t):
                z = pz + t * dz
                if z <= h + tol and z >= -h - tol:
                    cands[j] = t
    t = (-h - pz) / dz if dz != 0.0 else _INF
    if math.isfinite(t):
        bx, by = px + t * dx, py + t * dy
        if bx * bx + by * by <= r * r + tol * r:
            cands[2] = t
    best, j = _nearest(cands, lo, hi)
    if j < 0:
        return _INF, (0.0, 0.0, 0.0)
    if j == 2:
        return best, (0.0, 0.0, -1.0)
    nx, ny = px + best * dx, py + best * dy
    nz = k2 * (h - (pz + best * dz))
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    if norm == 0.0:
        return best, (0.0, 0.0, 1.0)
    return best, (nx / norm, ny / norm, nz / norm)


def _skew(a: np.ndarray) -> np.ndarray:
    """S with d @ S = d x a for row vectors d."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


_SKEW1, _SKEW2 = _skew(_AUX1), _skew(_AUX2)


def _perpendicular(d: np.ndarray) -> np.ndarray:
    """Unit vectors perpendicular to the rows of d (d x AUX1, or d x AUX2 where d ~ AUX1)."""
    c = _mat(d, _SKEW1)
    c2 = _dot(c, c)
    weak = (c2 < 0.1).nonzero()[0]
    if len(weak):
        c[weak] = _mat(d[weak], _SKEW2)
        c2[weak] = _dot(c[weak], c[weak])
    c /= np.sqrt(c2)[:, None]
    return c


def _full(x, m: int, dtype=np.float64) -> np.ndarray:
    """A per-ray parameter as an (m,) array; arrays pass through (not copied)."""
    return x if isinstance(x, np.ndarray) else np.full(m, x, dtype=dtype)


def _param(x, n: int, dtype, scalar):
    """Normalise a per-cast parameter: a Python scalar, or an (n,) array when it varies per ray.
    A uniform array collapses to its scalar: scalars unlock the cheap paths (no per-ray gathers,
    owner checks skipped for exclude_owner = -1, no t_far clamping for t_far = inf)."""
    if isinstance(x, (float, int)):
        return scalar(x)
    a = np.asarray(x, dtype=dtype)
    if a.ndim == 0:
        return scalar(a)
    a = a.reshape(n)
    if n == 0:
        return a
    if n <= _SMALL:  # list comparisons beat two numpy reductions on a few values; NaN never counts
        vals = a.tolist()
        if vals.count(vals[0]) == n:
            return scalar(vals[0])
    elif not np.count_nonzero(a != a[0]):
        return scalar(a[0])
    return a


def _strictly_increasing(rows: np.ndarray) -> bool:
    return len(rows) < 2 or not np.count_nonzero(rows[1:] <= rows[:-1])


def _best_per_row(rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Indices into (rows, t) of the smallest t of each distinct row (ties: the earliest)."""
    order = np.lexsort((t, rows))  # stable
    r = rows[order]
    first = np.empty(len(r), dtype=bool)
    first[0] = True
    np.not_equal(r[1:], r[:-1], out=first[1:])
    return order[first]
