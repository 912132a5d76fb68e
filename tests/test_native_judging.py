"""Judging and refinement in C (packets.c: sp_fast_pass, sp_exact_pass, sp_analytic) against the
engine's numpy path: the same distances, normals and shape ids bit for bit (``tobytes``, signed
zeros included), on random scenes and rays chosen where the arithmetic is delicate -- rays aimed at
vertices and edge midpoints, rays starting inside curved shells, rays parallel to caps or along
axes, overlapping curved shapes (rays continued past shells), a world far from the origin
(anchored tiers), moving bodies with owners, per-ray limits and exclusions, one-origin lidars.
``RayEngine.native = False`` is the numpy path on the same packet traversal."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from sensorium.server.raycast import exact, packets, trace
from sensorium.server.raycast.engine import Mount, Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Mesh, Plane, Pose, Sphere, tessellate

pytestmark = pytest.mark.skipif(packets.library() is None, reason=f"no packet path here: {packets.status()}")


def _unit(v):
    return v / np.linalg.norm(v, axis=1)[:, None]


def _rot(rng, aligned: bool) -> np.ndarray:
    if aligned:   # axis-aligned (exact zeros in the rotation: the signed zeros of normals matter)
        return np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], 3)[:, None] if rng.random() < 0.5 else np.eye(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _scene(precision, seed: int, offset=(0.0, 0.0, 0.0)):
    """Boxes, a rock mesh, spheres, cylinders and capsules (some overlapping), a floor, a moving
    robot with a round body (owner 0) and two small movers (owners 1, 2); everything shifted by
    ``offset``. Returns (engine, robot body, aim points: vertices, edge midpoints, centres)."""
    rng = np.random.default_rng(seed)
    off = np.asarray(offset, dtype=np.float64)
    eng = RayEngine(precision)
    eng.threads = 1
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose(np.eye(3), off))
    aims = []
    prims = [Box((0.5, 0.4, 1.0)), Box((2.0, 0.1, 0.8)), Sphere(0.4), Sphere(0.25), Cylinder(0.2, 1.5),
             Cylinder(0.3, 0.3), Capsule(0.15, 0.8), Capsule(0.3, 0.2)]
    for k, prim in enumerate(prims):
        at = rng.uniform(-2.0, 2.0, 3) * [1, 1, 0.2] + [0, 0, 0.6]
        if k in (3, 5):                 # overlapping the previous shape: rays continue past shells
            at = at_prev + rng.uniform(-0.15, 0.15, 3)  # noqa: F821 - set below on the first pass
        pose = Pose(_rot(rng, k % 2 == 0), at + off)
        eng.add_body([ShapeEntry(prim, Pose.identity(), True, True)], pose)
        v, f = tessellate(prim)
        w = pose.apply(v)
        aims += [w, (w[f[:, 0]] + w[f[:, 1]]) / 2, w[f].mean(axis=1)]
        at_prev = at                    # noqa: F841
    rock = trimesh.creation.icosphere(subdivisions=1, radius=0.3)
    rock_pose = Pose(_rot(rng, False), np.array([2.0, -2.0, 0.3]) + off)
    eng.add_body([ShapeEntry(Mesh(rock.vertices, rock.faces, closed=True), Pose.identity(), True, True)], rock_pose)
    aims.append(rock_pose.apply(rock.vertices))
    robot = eng.add_body([ShapeEntry(Cylinder(0.18, 0.1), Pose.identity(), True, True),
                          ShapeEntry(Box((0.3, 0.2, 0.05)), Pose(np.eye(3), np.array([0.0, 0.0, 0.07])), True, True)],
                         Pose(_rot(rng, True), np.array([0.1, 0.2, 0.06]) + off), owner=0, movable=True)
    for k, at in enumerate([(0.8, -0.2), (-0.7, 0.1)]):
        eng.add_body([ShapeEntry(Sphere(0.05), Pose.identity(), True, True)],
                     Pose(np.eye(3), np.array([*at, 0.05]) + off), owner=k + 1, movable=True)
    return eng, robot, np.vstack(aims)


def _casts(eng, robot, aims, seed: int, offset):
    """Every kind of cast the engine serves, three poses of the robot: a list of arrays."""
    rng = np.random.default_rng(seed + 100)
    off = np.asarray(offset, dtype=np.float64)
    az = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    el = np.linspace(-0.5, 0.3, 12)
    A, E = np.meshgrid(az, el)
    d_loc = np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)
    mount = Mount(np.full(len(d_loc), robot), own=True)
    out = []
    for step in range(3):
        pose = Pose(Pose.from_axis_angle((0, 0, 1), 0.4 * step, [0, 0, 0]).rotation,
                    np.array([0.1 + 0.2 * step, 0.2, 0.06]) + off)
        eng.set_body_pose(robot, pose)
        o = pose.apply(np.array([[0.0, 0.0, 0.03]]))[0]          # inside the body's shell
        O1 = np.broadcast_to(o, d_loc.shape)
        D1 = d_loc @ pose.rotation.T
        out.append(eng.cast(O1, D1, 0.0, 6.0, kind=RayKind.VISUAL, mount=mount, distance_only=True).distance)
        h = eng.cast(O1, D1, 0.0, 6.0, kind=RayKind.VISUAL)
        out += [h.distance, h.normal, h.shape]
        # aimed at vertices, edge midpoints and triangle centres, from scattered eyes
        eyes = rng.uniform(-3.0, 3.0, (len(aims), 3)) * [1, 1, 0.4] + [0, 0, 0.8] + off
        D2 = _unit(aims + rng.normal(size=aims.shape) * rng.choice([0.0, 1e-7, 1e-3], (len(aims), 1)) - eyes)
        far = rng.uniform(0.5, 8.0, len(D2))
        near = rng.choice([0.0, 0.01, 0.2], len(D2))
        excl = rng.choice([-1, 0, 1, 2], len(D2))
        for kind in (RayKind.BOUNDING, RayKind.VISUAL):
            h = eng.cast(eyes, D2, near, far, kind=kind, exclude_owner=excl)
            out += [h.distance, h.normal, h.shape]
            out.append(eng.cast(eyes, D2, near, far, kind=kind, distance_only=True).distance)
            # many origins well inside the tier's sphere, one start for all rays: the C pass rounds
            # the rows to float32 and shifts them itself
            inner = (eyes - off) * 0.4 + off
            for start in (0.0, 0.01):
                h = eng.cast(inner, D2, start, far, kind=kind, exclude_owner=excl)
                out += [h.distance, h.normal, h.shape]
        # starting inside shapes and on surfaces, axis-parallel directions
        starts = aims[rng.integers(0, len(aims), 600)] + rng.normal(size=(600, 3)) * 0.05
        D3 = rng.normal(size=(600, 3))
        D3[:100, :2] = 0.0
        D3[100:200, 2] = 0.0
        D3 = _unit(D3)
        h = eng.cast(starts, D3, 0.0, np.inf, kind=RayKind.BOUNDING)
        out += [h.distance, h.normal, h.shape]
        for k in (1, 3, 17, 70):        # small batches (the plain-float shortcuts around the passes)
            h = eng.cast(starts[:k], D3[:k], 0.0, 5.0, kind=RayKind.VISUAL, exclude_owner=0)
            out += [h.distance, h.normal, h.shape]
    return out


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (3.0e4, -1.0e4, 0.0)])
@pytest.mark.parametrize("precision", [Precision.FAST, Precision.EXACT])
@pytest.mark.parametrize("seed", [0, 1])
def test_c_judging_gives_the_numpy_answers_bit_for_bit(precision, seed, offset, monkeypatch):
    calls = {"fast": 0, "exact": 0, "rays": 0}
    fast0, exact0 = trace.TierTracer._fast_native, trace.TierTracer._exact_native

    def fast(self, *a, **k):
        got = fast0(self, *a, **k)
        calls["fast"] += got is not None
        return got

    def exact_(self, tier, st, Ot, D, *a, **k):
        calls["exact"] += 1
        calls["rays"] += len(D)
        return exact0(self, tier, st, Ot, D, *a, **k)

    monkeypatch.setattr(trace.TierTracer, "_fast_native", fast)
    monkeypatch.setattr(trace.TierTracer, "_exact_native", exact_)
    results = {}
    for native in (False, True):
        eng, robot, aims = _scene(precision, seed, offset)
        eng.native = native
        results[native] = (_casts(eng, robot, aims, seed, offset), dict(eng.counters))
    ref, got = results[False][0], results[True][0]
    assert len(ref) == len(got)
    for i, (a, b) in enumerate(zip(ref, got)):
        assert a.tobytes() == b.tobytes(), (i, np.flatnonzero((a != b).reshape(len(a), -1).any(axis=1))[:5])
    assert np.isfinite(ref[0]).mean() > 0.5 and np.isfinite(ref[4]).mean() > 0.3    # the casts do hit
    # the C passes did the work (FAST's judging; EXACT's whole loop), and on the rays where the
    # arithmetic is delicate: guards met, rays continued past shells (the same counts as numpy's)
    if precision is Precision.FAST:
        assert calls["fast"] > 50
    else:
        assert calls["exact"] > 50
        c_np, c_c = results[False][1], results[True][1]
        assert c_c["edge_guard_hits"] == c_np["edge_guard_hits"] > 0
        assert c_c["continued_rays"] == c_np["continued_rays"] > 0


def _tier_of_curved(seed: int):
    """A static tier of spheres, cylinders and capsules at random poses, some axis-aligned."""
    rng = np.random.default_rng(seed)
    eng = RayEngine(Precision.EXACT)
    for k in range(9):
        prim = (Sphere(rng.uniform(0.2, 0.8)), Cylinder(rng.uniform(0.2, 0.8), rng.uniform(0.1, 1.5)),
                Capsule(rng.uniform(0.2, 0.8), rng.uniform(0.0, 1.5)))[k % 3]
        eng.add_body([ShapeEntry(prim, Pose.identity(), True, True)],
                     Pose(_rot(rng, k >= 5), rng.uniform(-3.0, 3.0, 3)))
    eng.cast(np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]]))
    return eng, eng._static_tier("bounding")


@pytest.mark.parametrize("m", [1, 7, 300, 1500])     # one pass of mixed kinds up to 1,024 rows, per kind above
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_c_analytic_gives_the_numpy_answers_bit_for_bit(seed, m):
    """The true-surface intersection of curved shapes (shape frame in and out, candidates, nearest,
    normal) in C against the engine's numpy ``_analytic``: one shape for all rows (one matrix),
    several kinds in one pass, and kind by kind -- t and normals bit for bit, origins inside,
    rays parallel to caps and along axes, limits cutting hits."""
    eng, tier = _tier_of_curved(seed)
    rng = np.random.default_rng(seed + 10)
    st = tier.native(True)
    for one in (True, False):
        slots = np.full(m, rng.integers(len(tier.c_code))) if one else rng.integers(0, len(tier.c_code), m)
        c = tier.c_pos[slots]
        O = c + rng.uniform(-1.5, 1.5, (m, 3))
        O[: m // 5] = c[: m // 5] + rng.uniform(-0.2, 0.2, (m // 5, 3))       # inside
        D = _unit(c + rng.uniform(-0.6, 0.6, (m, 3)) - O)
        axis = tier.c_rot[slots][:, :, 2]                                     # the shape's z axis
        k = m // 3
        D[k:k + m // 10] = axis[k:k + m // 10]                                # along the axis
        side = np.cross(axis, [0.3, 0.5, 0.8])
        D[k + m // 10:k + m // 5] = _unit(side[k + m // 10:k + m // 5])        # parallel to the caps
        lo = rng.uniform(0.0, 0.3, m)
        hi = np.where(rng.random(m) < 0.8, lo + rng.uniform(0.0, 4.0, m), np.inf)
        with np.errstate(all="ignore"):
            t_ref, n_ref = eng._analytic(tier, slots, O, D, lo, hi)
            t_only, _ = eng._analytic(tier, slots, O, D, lo, hi, normals=False)
        t, t2 = np.empty(m), np.empty(m)
        n = np.empty((m, 3))
        lib = packets.library()
        s64, Oc, Dc = slots.astype(np.int64), np.ascontiguousarray(O), np.ascontiguousarray(D)
        for tt, nn in ((t, n), (t2, None)):
            lib.sp_analytic(st, m, s64.ctypes.data, Oc.ctypes.data, Dc.ctypes.data, lo.ctypes.data, hi.ctypes.data,
                            tt.ctypes.data, None if nn is None else nn.ctypes.data)
        assert t.tobytes() == t_ref.tobytes()
        assert n.tobytes() == n_ref.tobytes()
        assert t2.tobytes() == t_only.tobytes()
        if m >= 300:
            assert 0.2 < np.isfinite(t).mean() < 0.95                          # hits and misses


@pytest.mark.parametrize("distance_only", [False, True])
def test_fast_general_loop_refines_shells_left_from_inside_in_c_with_the_numpy_answers(distance_only, monkeypatch):
    """FAST's general loop (the rays _trace_fast redoes: a curved shell hit from inside) takes the
    true surface from packets.analytic: t, shapes and normals bit for bit those of the numpy
    ``_analytic`` (the helper switched off), for rays from inside and outside spheres, cylinders
    and capsules, with limits cutting some hits; and the C pass is the one used."""
    rng = np.random.default_rng(8)
    eng, tier = _tier_of_curved(3)
    eng.precision = Precision.FAST
    m = 3000
    slots = rng.integers(0, len(tier.c_code), m)
    c = tier.c_pos[slots]
    O = c + rng.uniform(-0.15, 0.15, (m, 3))
    O[m // 2:] = c[m // 2:] + rng.uniform(-2.0, 2.0, (m - m // 2, 3))
    D = _unit(rng.normal(size=(m, 3)))
    lim = np.where(rng.random(m) < 0.7, rng.uniform(0.05, 4.0, m), np.inf)
    eps64 = 1e-9 + 1e-14 * float(np.abs(O).max())
    calls = []
    real = packets.analytic

    def counted(*a, **k):
        calls.append(len(a[1]))
        return real(*a, **k)

    monkeypatch.setattr(packets, "analytic", counted)
    with np.errstate(all="ignore"):
        got = eng._trace_loop(tier, O, D, 0.0, lim, -1, eps64, exact=False, distance_only=distance_only)
    assert sum(calls) >= 40                                  # shells left from inside, refined in C
    monkeypatch.setattr(packets, "analytic", lambda *a, **k: None)
    with np.errstate(all="ignore"):
        want = eng._trace_loop(tier, O, D, 0.0, lim, -1, eps64, exact=False, distance_only=distance_only)
    for g, w in zip(got, want):
        assert g.tobytes() == w.tobytes()
    assert 0.3 < np.isfinite(got[0]).mean() < 1.0


def test_numpy_minimum_semantics_the_c_code_follows():
    """packets.c's np_min/np_max and its float32 comparisons follow numpy: NaN wins, the second
    operand on ties (signed zeros), float32 arrays compared with Python floats in float32."""
    assert math.copysign(1.0, np.minimum(-0.0, 0.0)) == 1.0 and math.copysign(1.0, np.minimum(0.0, -0.0)) == -1.0
    assert math.isnan(np.minimum(np.nan, 1.0)) and math.isnan(np.minimum(1.0, np.nan))
    x = np.float32(1e-4)
    assert float(x) < 1e-4 and not (np.array([x]) < 1e-4)[0]          # compared as float32(1e-4)
    assert exact._BARY_TOL == 1e-9                                      # the tolerance written in packets.c


@pytest.mark.parametrize("visual", [True, False])
def test_axis_aligned_plane_without_blas_gives_the_blas_answers(visual, monkeypatch):
    """A floor (or any axis-aligned plane) met by rays of many origins: D . n taken as one column
    times the normal's component instead of the BLAS product -- the same hits, distances, normals
    and shape ids bit for bit (rays along the plane, from below and above, on it, with -0.0)."""
    from sensorium.server.raycast import planes

    rng = np.random.default_rng(5)
    n = 5000
    O = rng.uniform(-3.0, 3.0, (n, 3))
    O[:200, 2] = 0.25                                     # on the plane
    D = _unit(rng.normal(size=(n, 3)))
    D[200:400, 2] = 0.0                                   # along it
    D[400:500, 2] = -0.0
    D[500:600] = [0.0, 0.0, -1.0]
    out = {}
    for lean in (True, False):
        if not lean:   # the general (n,3) @ (3,P) product for every plane
            monkeypatch.setattr(planes._Planes, "refresh", lambda self, epoch, f=planes._Planes.refresh: (
                f(self, epoch), setattr(self, "axis", -1)))
        res = []
        for c in (1.0, -1.0):
            eng = RayEngine(Precision.EXACT)
            rot = np.eye(3) if c == 1.0 else np.diag([1.0, -1.0, -1.0])   # a ceiling: normal -z
            eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose(rot, np.array([0.0, 0.0, 0.25])))
            kind = RayKind.VISUAL if visual else RayKind.BOUNDING
            h = eng.cast(O, D, 0.0, np.inf, kind=kind)
            res += [h.distance, h.normal, h.shape, eng.cast(O, D, 0.0, 4.0, kind=kind, distance_only=True).distance]
        out[lean] = res
    for a, b in zip(out[True], out[False]):
        assert a.tobytes() == b.tobytes()
    assert 0.2 < np.isfinite(out[True][0]).mean() < 0.8


def test_c_refinement_in_a_coarse_float32_frame_gives_the_numpy_answers(monkeypatch):
    """A room 1e4 m out with a landmark box at the origin in ONE static tier (float32 resolution
    ~1 mm at the room): Embree reports neighbouring faces' triangles, so EXACT takes its vertex
    rings and the nearby-triangle search -- in C the same distances, normals and shapes bit for
    bit as numpy's (which is checked to have used both)."""
    from sensorium.server.raycast import refine

    boxes = [((10, 10, 0.2), (0, 0, -0.1)), ((10, 10, 0.2), (0, 0, 3.1)), ((0.2, 10.4, 3.4), (5.1, 0, 1.5)),
             ((0.2, 10.4, 3.4), (-5.1, 0, 1.5)), ((10, 0.2, 3), (0, 5.1, 1.5)), ((10, 0.2, 3), (0, -5.1, 1.5)),
             ((1.0, 0.6, 0.8), (2.0, 1.5, 0.4)), ((0.7, 1.3, 1.1), (-2.5, -1.0, 0.55))]
    base = np.array([1e4, 5e3, 0.0])
    n = 65536
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    d = np.c_[np.sqrt(1 - z * z) * np.cos(i * np.pi * (3 - 5 ** 0.5)), np.sqrt(1 - z * z) * np.sin(i * np.pi * (3 - 5 ** 0.5)), z]
    used = {"nearby": 0}
    nearby0 = refine.Refiner._nearby_triangles

    def nearby(self, *a):
        ok, t, tri = nearby0(self, *a)
        used["nearby"] += int(ok.sum())
        return ok, t, tri

    monkeypatch.setattr(refine.Refiner, "_nearby_triangles", nearby)
    out = {}
    for native in (False, True):
        e = RayEngine(Precision.EXACT)
        e.threads = 1
        e.native = native
        for size, c in boxes:
            e.add_body([ShapeEntry(Box(size), Pose.identity(), True, True)], Pose(np.eye(3), base + c))
        e.add_body([ShapeEntry(Box((1, 1, 1)), Pose.identity(), True, True)], Pose.identity())
        h = e.cast(np.tile(base + [0.31, -0.17, 1.23], (n, 1)), d)
        out[native] = [h.distance, h.normal, h.shape]
    for a, b in zip(out[False], out[True]):
        assert a.tobytes() == b.tobytes()
    assert used["nearby"] > 0



def test_rows_into_a_body_frame_in_c_are_the_engine_sums():
    """A lidar's beams gathered and turned into its body's frame in one C pass: the bits of
    ``exact._to_frame`` (small and large batches, a rotation with exact zeros)."""
    rng = np.random.default_rng(4)
    D = np.ascontiguousarray(_unit(rng.normal(size=(5000, 3))))
    for R in (_rot(rng, False), _rot(rng, True)):
        for k in (65, 3000):
            rows = np.sort(rng.choice(len(D), k, replace=False)).astype(np.int64)
            assert packets.to_frame_rows(D, rows, R).tobytes() == exact._to_frame(D.take(rows, axis=0), R).tobytes()


@pytest.mark.parametrize("seed", [0, 1])
def test_c_screening_of_starts_inside_curved_shells_is_the_numpy_screening(seed, monkeypatch):
    """The pre-pass's screening for many rays of many origins (a batched world's copies): the start
    points inside each shell's extent, listed in one C pass (packets.inside_shells), are those of
    refine._inside_shell shell by shell, in its order, for scalar and per-ray starts and one shared
    origin; a point at a sphere's centre is inside it, one just beyond its bound is not; and whole
    casts of such rays give the numpy path's answers bit for bit."""
    from sensorium.server.raycast.refine import Refiner

    eng, tier = _tier_of_curved(seed)
    rng = np.random.default_rng(seed + 7)
    k = len(tier.c_pos)
    eyes = tier.c_pos[rng.integers(0, k, 40)] + rng.normal(size=(40, 3)) * 0.4   # many inside, many not
    O = np.repeat(eyes, 500, axis=0)
    D = _unit(rng.normal(size=(len(O), 3)))
    shells = list(range(k))
    for Ot, lo in ((O, 0.01), (O, rng.uniform(0.0, 0.3, len(O))), (np.broadcast_to(eyes[0], O.shape), 0.2)):
        S = Ot + (lo[:, None] if isinstance(lo, np.ndarray) else lo) * D
        masks = [Refiner._inside_shell(tier, s, S).nonzero()[0] for s in shells]
        want_rows = np.concatenate(masks)
        want_slots = np.concatenate([np.full(len(r), s) for s, r in zip(shells, masks)])
        rows, slots = packets.inside_shells(tier, Ot, D, lo, shells)
        assert rows.tolist() == want_rows.tolist() and slots.tolist() == want_slots.tolist()
        assert len(rows) > 100 or Ot.strides[0] == 0
    sph = int(np.flatnonzero(tier.c_code == exact._SPHERE)[0])
    b = math.sqrt(tier.c_bound2[sph])
    pts = tier.c_pos[sph] + np.array([[0.0, 0.0, 0.0], [b * 1.001, 0.0, 0.0]])
    rows, _ = packets.inside_shells(tier, pts, np.tile([0.0, 0.0, 1.0], (2, 1)), 0.0, [sph])
    assert rows.tolist() == [0]
    screened = []
    inside0 = packets.inside_shells
    dense = []
    monkeypatch.setattr(packets, "inside_shells", lambda *a, **k: dense.append(k.get("bound_first")) or
                        screened.append(inside0(*a, **k)) or screened[-1])
    # the dense pass (fewer rays): bounding spheres first, then the extents, pairs by row
    S = O + 0.01 * D
    cp = tier.c_pos
    d2 = (S[:, 0:1] - cp[:, 0]) ** 2 + (S[:, 1:2] - cp[:, 1]) ** 2 + (S[:, 2:3] - cp[:, 2]) ** 2
    inside = np.stack([Refiner._inside_shell(tier, s, S) for s in shells], axis=1)
    want_rows, want_slots = ((d2 <= tier.c_bound2) & inside).nonzero()
    rows, slots = packets.inside_shells(tier, O, D, 0.01, shells, bound_first=True)
    order = np.lexsort((slots, rows))
    assert rows[order].tolist() == want_rows.tolist() and slots[order].tolist() == want_slots.tolist()
    hits = {}
    for native in (False, True):
        eng.native = native
        h = eng.cast(O, D, 0.01, 6.0, kind=RayKind.BOUNDING)
        few = eng.cast(O[:1500], D[:1500], 0.01, 6.0, kind=RayKind.BOUNDING)   # 1,500 x 9 pairs: the dense pass
        hits[native] = (h.distance, h.normal, h.shape, few.distance, few.normal, few.shape)
    for a, c in zip(hits[False], hits[True]):
        assert a.tobytes() == c.tobytes()
    assert np.isfinite(hits[True][0]).mean() > 0.3
    assert sum(len(r) for r, _ in screened) > 1000       # the C screening found the starts inside shells
    assert True in dense and False in dense              # both screenings ran: by shell and dense
