"""copies.CopyRays' lean path (FAST: the planes, the static tier and the broad phase in one C call,
sp_copy_cast): the very answers of the general path (RayEngine.cast on the static engine, then the
broad phase), bit for bit, for rays that hit the other robot, graze it, hit the floor plane, need
the general loop's redo, or need a stage the call does not do (then the general path answers)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.raycast import packets, trace
from sensorium.server.raycast.kinds import RayKind
from sensorium.server.sim.batched import BatchedSimulation
from tests.test_batched_sim import arena

pytestmark = pytest.mark.skipif(packets.library() is None, reason=f"no packet path here: {packets.status()}")

R_EPUCK = 0.035   # the e-puck's body: a cylinder of radius 0.035 m, 0.05 m high, centred on its pose
L = 0.5           # each copy's origin lies this far from its e-puck's axis


def _copies(n: int) -> tuple[BatchedSimulation, np.ndarray]:
    """n copies, each e-puck at its own spot in the open middle of the arena (no curved shell near)."""
    bs = BatchedSimulation(arena(3), n, precision="fast")
    bs.reset(np.arange(n), [3] * n)
    epuck = bs.slot("epuck")
    centres = np.array([[-0.3 + 0.05 * c, 0.1 - 0.04 * c, 0.01] for c in range(n)])
    for c in range(n):
        bs.set_pose(c, epuck, centres[c].tolist(), rotation=[0, 0, 1, 0.3 * c])
    return bs, centres


def _scan(centres: np.ndarray, sweep: int = 200) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per copy: an origin L before its e-puck (-x), 360 level beams all round and ``sweep`` beams
    across the e-puck's silhouette (grazing it). (origins, directions, each ray's copy, origin rows)."""
    edge = math.asin(R_EPUCK / L)
    angles = np.concatenate([np.arange(360) * (2.0 * math.pi / 360), np.linspace(0.9 * edge, 1.1 * edge, sweep)])
    dirs = np.stack([np.cos(angles), np.sin(angles), np.zeros(len(angles))], axis=1)
    rows = centres - np.array([L, 0.0, 0.0])
    W = len(dirs)
    return np.repeat(rows, W, axis=0), np.tile(dirs, (len(rows), 1)), np.repeat(np.arange(len(rows)), W), rows


def _both(bs: BatchedSimulation, *args, **kw):
    """The cast through the lean path (asserting it took it) and through the general path."""
    rays = bs.rays
    before = rays.counters["lean_casts"]
    lean = rays.cast(*args, **kw)
    assert rays.counters["lean_casts"] == before + 1
    rays.lean = False
    try:
        general = rays.cast(*args, **kw)
    finally:
        rays.lean = True
    assert rays.counters["lean_casts"] == before + 1
    return lean, general


def _same(a, b) -> None:
    for name in ("distance", "normal", "shape"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and x.shape == y.shape, name
            assert x.tobytes() == y.tobytes(), (name, np.flatnonzero((x != y).reshape(len(x), -1).any(axis=1))[:5])


@pytest.mark.parametrize("distance_only", [True, False])
@pytest.mark.parametrize("far", ["scalar", "per ray"])
def test_lidar_scans_that_hit_and_graze_the_other_robot_answer_as_the_general_path(distance_only, far):
    n = 6
    bs, centres = _copies(n)
    O, D, copy, rows = _scan(centres)
    W = len(D) // n
    # (per ray: a strided view, as a caller may pass one)
    t_far = 6.0 if far == "scalar" else np.linspace(2.0, 6.0, 2 * len(D))[::2]
    scout = bs.slot("scout")
    pairs = bs.rays.counters["mover_pairs"]
    lean, general = _both(bs, O, D, 0.02, t_far, RayKind.VISUAL, copy, bs.rot, bs.pos, -1, scout,
                          distance_only=distance_only, coherent=True, origin_rows=rows, run=W)
    _same(lean, general)
    assert bs.rays.counters["mover_pairs"] > pairs
    d = lean.distance.reshape(n, W)
    # the beam straight at the e-puck: its shell (a circumscribed 36-gon) just before L - r
    assert d[:, 0] == pytest.approx(L - R_EPUCK, abs=2e-4)
    sweep = d[:, 360:]
    on_it = sweep < L
    assert on_it.any() and (~on_it).any()      # the sweep crosses the silhouette: grazing beams on both sides
    if not distance_only:
        epuck_shape = bs.rays.shape_offset + 0
        assert (lean.shape.reshape(n, W)[:, 0] == epuck_shape).all()
        assert (lean.shape.reshape(n, W)[:, 360:][on_it] == epuck_shape).all()
        normal0 = lean.normal.reshape(n, W, 3)[:, 0]
        assert normal0[:, 0] == pytest.approx(-np.ones(n), abs=0.01)    # facing the origin


def test_sonar_rays_with_the_floor_per_ray_exclusions_and_mounts_answer_as_the_general_path():
    """BOUNDING rays tilted down to the floor plane (the plane's hits merged with the mesh's: walls
    and crates nearer than the floor win), per-ray excluded and mount slots, normals and shapes."""
    n = 5
    bs, centres = _copies(n)
    rng = np.random.default_rng(7)
    k = 5
    rows = centres - np.array([L, 0.0, -0.04])
    W = 16 * k
    dirs = rng.normal(size=(n * W, 3))
    dirs[:, 2] = -np.abs(dirs[:, 2]) * 0.2
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    dirs[::W] = [1.0, 0.0, 0.0]                 # each copy's first ray at its e-puck
    O = np.repeat(rows, W, axis=0)
    copy = np.repeat(np.arange(n), W)
    excl = np.where(np.arange(n * W) % 3 == 0, bs.slot("scout"), -1)
    mount = np.where(np.arange(n * W) % 4 == 1, bs.slot("epuck"), -1)
    lean, general = _both(bs, O, dirs, 0.0, 3.0, RayKind.BOUNDING, copy, bs.rot, bs.pos, excl, mount,
                          origin_rows=rows, run=W)
    _same(lean, general)
    floor = bs.scene.engine._entries.index(next(e for e in bs.scene.engine._entries if type(e.primitive).__name__ == "Plane"))
    assert (lean.shape == floor).any() and (lean.shape == bs.rays.shape_offset).any()
    z = O[:, 2] + lean.distance * dirs[:, 2]
    on_floor = lean.shape == floor
    assert z[on_floor] == pytest.approx(np.zeros(np.count_nonzero(on_floor)), abs=1e-12)


def test_the_kept_static_fields_follow_a_changed_static_world():
    """The lean job's plane and static-tier fields are kept between casts (CopyRays._static_fields):
    after a wall is removed (the static tier rebuilt) and then the floor (no plane left), the next
    lean cast answers as the general path in the changed world, not with the kept pointers (a
    field kept past the change fails it)."""
    n = 3
    bs, centres = _copies(n)
    st = bs.rays.static
    rows = centres - np.array([L, 0.0, -0.04])
    W = 120
    a = np.arange(W) * (2.0 * math.pi / W)
    dirs = np.tile(np.stack([np.cos(a), np.sin(a), np.where(np.arange(W) % 2, -0.08, 0.0)], axis=1), (n, 1))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    O = np.repeat(rows, W, axis=0)
    copy = np.repeat(np.arange(n), W)
    args = (O, dirs, 0.0, 6.0, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1)
    first, general = _both(bs, *args, origin_rows=rows, run=W)
    _same(first, general)
    floor_shape = next(i for i, e in enumerate(st._entries) if type(e.primitive).__name__ == "Plane")
    on_floor = first.shape == floor_shape
    on_wall = ~on_floor & (first.shape >= 0) & (first.shape < bs.rays.shape_offset)   # (a solid, not a robot)
    assert on_floor.any() and on_wall.any()
    wall_shape = int(first.shape[on_wall][0])
    st.remove_body(st._shape_body[wall_shape])
    no_wall, general = _both(bs, *args, origin_rows=rows, run=W)
    _same(no_wall, general)
    assert not (no_wall.shape == wall_shape).any() and (no_wall.shape == floor_shape).any()
    st.remove_body(st._shape_body[floor_shape])
    no_floor, general = _both(bs, *args, origin_rows=rows, run=W)
    _same(no_floor, general)
    assert not (no_floor.shape == floor_shape).any()
    assert (no_floor.distance[on_floor] > first.distance[on_floor]).all()   # past where the floor was


def test_rays_from_a_crates_faces_take_the_redo_and_answer_as_the_general_path(monkeypatch):
    """Origins on the crate's side faces (t_near 0): rays into the crate first meet the face they
    start on (a possible self-hit, which FAST redoes in the general loop) and then its far side."""
    bs, _ = _copies(2)
    tier = bs.rays.static._static_tier("bounding")
    crate = [i for i in np.flatnonzero(tier.tri_shape[:-1] == 5).tolist() if abs(tier.normal[i, 2]) < 0.5]
    rows = np.array([tier.V[tier.F[i]].mean(axis=0) for i in crate])
    inward = -tier.normal[crate]
    W = 10
    rng = np.random.default_rng(3)
    dirs = np.repeat(inward, W, axis=0) + 0.3 * rng.normal(size=(len(rows) * W, 3))
    dirs[::W] = inward
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    O = np.repeat(rows, W, axis=0)
    copy = np.repeat(np.arange(len(rows)) % 2, W)
    loops = []
    real = trace.TierTracer._trace_loop
    monkeypatch.setattr(trace.TierTracer, "_trace_loop", lambda self, *a, **k: loops.append(len(a[1])) or real(self, *a, **k))
    lean, general = _both(bs, O, dirs, 0.0, 2.0, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, origin_rows=rows, run=W)
    assert len(loops) == 2 and loops[0] == loops[1] > 0      # the lean cast redid the rays the general one did
    _same(lean, general)
    # straight in: the crate is 0.3 m across
    assert lean.distance[::W] == pytest.approx(np.full(len(rows), 0.3), abs=1e-6)


def test_a_cast_whose_data_needs_a_general_stage_falls_back_with_the_same_answers():
    """Origins within reach of a curved shell (the sphere of radius 0.12 m at (-0.8, 0.9, 0.12): the
    pre-pass applies) and per-ray t_near: the general path answers (lean_casts unchanged)."""
    bs, centres = _copies(2)
    rows = np.array([[-0.8 + 0.13, 0.9, 0.12], [-0.8, 0.9 - 0.135, 0.12]])
    W = 90
    a = np.arange(W) * (2.0 * math.pi / W)
    D = np.tile(np.stack([np.cos(a), np.sin(a), np.zeros(W)], axis=1), (2, 1))
    O = np.repeat(rows, W, axis=0)
    copy = np.repeat(np.arange(2), W)
    rays = bs.rays
    for t_near in (0.02, np.full(2 * W, 0.02)):
        before = rays.counters["lean_casts"]
        got = rays.cast(O, D, t_near, 3.0, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, origin_rows=rows, run=W)
        assert rays.counters["lean_casts"] == before
        rays.lean = False
        try:
            _same(got, rays.cast(O, D, t_near, 3.0, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, origin_rows=rows,
                                 run=W))
        finally:
            rays.lean = True
        # the ray toward the sphere's centre starts (t_near) inside it: the pre-pass's true surface,
        # where the ray leaves the sphere, 0.13 + 0.12 m on
        assert got.distance[W // 2] == pytest.approx(0.25, abs=1e-9)


def test_without_the_packet_helper_the_batched_cast_answers_as_the_lean_path(monkeypatch):
    """SENSORIUM_PACKETS=0 (embreex, numpy judging): no lean path, and incoherent rays get the lean
    path's answers bit for bit (incoherent packets are embreex's answers; the C judging numpy's)."""
    n = 3
    bs, centres = _copies(n)
    O, D, copy, rows = _scan(centres, sweep=40)
    W = len(D) // n
    args = (O, D, 0.02, 6.0, RayKind.VISUAL, copy, bs.rot, bs.pos, -1, bs.slot("scout"))
    lean = bs.rays.cast(*args, origin_rows=rows, run=W)
    assert bs.rays.counters["lean_casts"] == 1
    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.setenv("SENSORIUM_PACKETS", "0")
    assert packets.library() is None
    off, _ = _copies(n)
    plain = off.rays.cast(O, D, 0.02, 6.0, RayKind.VISUAL, copy, off.rot, off.pos, -1, off.slot("scout"),
                          origin_rows=rows, run=W)
    assert off.rays.counters["lean_casts"] == 0 and off.rays.counters["mover_pairs"] > 0
    _same(lean, plain)
    assert plain.distance.reshape(n, W)[:, 0] == pytest.approx(L - R_EPUCK, abs=2e-4)


@pytest.mark.parametrize("rows_given", [True, False])
@pytest.mark.parametrize("distance_only", [True, False])
def test_rays_from_many_origins_aimed_at_a_curved_shell_answer_as_the_general_path(rows_given, distance_only):
    """A few rays per origin (an e-puck's 3 per sensor: more than a quarter as many origins as rays)
    or no origin rows at all, aimed at the arena's sphere (radius 0.12 m at (-0.8, 0.9, 0.12)) from
    around it, none within reach of it: the call screens every origin against the shells itself and
    answers (the general path runs its pre-pass over every ray and finds nothing); the same bits,
    the sphere's true surface where a ray meets it. One origin inside the sphere: the general path."""
    bs, _ = _copies(4)
    rng = np.random.default_rng(7)
    centre = np.array([-0.8, 0.9, 0.12])
    k = 300                                        # origins, 0.2-0.6 m from the sphere's centre
    ang = rng.uniform(0.0, 2.0 * math.pi, k)
    dist = rng.uniform(0.2, 0.6, k)
    rows = centre + np.stack([dist * np.cos(ang), dist * np.sin(ang), rng.uniform(-0.05, 0.05, k)], axis=1)
    spread = np.array([-0.2, 0.0, 0.2])            # three rays per origin about the direction to the centre
    toward = np.arctan2(centre[1] - rows[:, 1], centre[0] - rows[:, 0])
    a = (toward[:, None] + spread[None, :]).reshape(-1)
    D = np.stack([np.cos(a), np.sin(a), np.zeros(len(a))], axis=1)
    O = np.repeat(rows, 3, axis=0)
    copy = np.repeat(np.arange(k) % 4, 3)
    kw = {"origin_rows": rows, "run": 3} if rows_given else {}
    lean, general = _both(bs, O, D, 0.0, 1.5, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, False, distance_only, **kw)
    _same(lean, general)
    # the middle ray of each origin heads for the centre: it meets the true sphere 0.12 m short of it
    gap = np.linalg.norm((rows - centre)[:, :2], axis=1)
    hit = np.hypot(gap, (rows - centre)[:, 2])
    mid = lean.distance[1::3]
    straight = np.abs((rows - centre)[:, 2]) < 1e-9
    assert np.isfinite(mid).all() and (mid <= hit - 0.11).all()
    assert np.count_nonzero(straight) == 0 or np.allclose(mid[straight], hit[straight] - 0.12, atol=1e-9)
    # an origin inside the sphere (0.115 m from its centre): the general path answers (its pre-pass)
    rows2 = rows.copy()
    rows2[5] = centre + np.array([0.115, 0.0, 0.0])
    O2 = np.repeat(rows2, 3, axis=0)
    kw2 = {"origin_rows": rows2, "run": 3} if rows_given else {}
    before = bs.rays.counters["lean_casts"]
    got = bs.rays.cast(O2, D, 0.0, 1.5, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, False, distance_only, **kw2)
    assert bs.rays.counters["lean_casts"] == before
    bs.rays.lean = False
    try:
        _same(got, bs.rays.cast(O2, D, 0.0, 1.5, RayKind.BOUNDING, copy, bs.rot, bs.pos, -1, -1, False, distance_only,
                                **kw2))
    finally:
        bs.rays.lean = True
