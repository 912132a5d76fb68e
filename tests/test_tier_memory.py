"""A tier's per-triangle arrays, made lean (int32 vertex rings, blocks of triangles, no copies):
the same values as the direct whole-array constructions they replace (the engine's answers rest on
them bit for bit; tests/test_native_judging.py and tests/test_golden_outputs.py check the casts)."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.server.raycast import packets, tiers
from sensorium.server.raycast.exact import _dot
from sensorium.server.raycast.guards import risky_edges
from sensorium.server.world.geometry import Box, Mesh, Pose, Sphere


def _fan_and_grid() -> tuple[np.ndarray, np.ndarray]:
    """A fan of 300 triangles around one hub vertex (valence 300) beside a 6x6 grid (valence 6)."""
    k = 300
    ang = np.linspace(0.0, 2.0 * np.pi, k, endpoint=False)
    fan_v = np.vstack([[0.0, 0.0, 0.0], np.c_[np.cos(ang), np.sin(ang), np.zeros(k)]])
    fan_f = np.c_[np.zeros(k, dtype=np.int64), 1 + np.arange(k), 1 + (np.arange(k) + 1) % k]
    x, y = np.meshgrid(np.arange(7.0), np.arange(7.0), indexing="ij")
    grid_v = np.c_[x.ravel() + 5.0, y.ravel(), np.zeros(49)]
    i = (np.arange(6)[:, None] * 7 + np.arange(6)[None]).ravel()
    grid_f = np.r_[np.c_[i, i + 7, i + 8], np.c_[i, i + 8, i + 1]] + len(fan_v)
    return np.vstack([fan_v, grid_v]), np.vstack([fan_f, grid_f])


def test_vertex_rings_list_each_corners_triangles_in_order_from_three_entries_per_triangle():
    V, F = _fan_and_grid()
    ring = tiers.VertexRings(F.astype(np.int32), len(V))
    assert ring.tri_of.dtype == np.int32 and len(ring.tri_of) == 3 * len(F)   # not the fan's 300² ring entries
    having = [sorted(np.flatnonzero((F == v).any(axis=1)).tolist()) for v in range(len(V))]
    want = [having[f[0]] + having[f[1]] + having[f[2]] for f in F]
    assert ring.sizes(np.arange(len(F))).tolist() == [len(w) for w in want]
    rows = np.array([5, 0, 310, 299, 0], dtype=np.int64)   # any triangles, repeated, in any order
    pos, members = ring.rows(rows)
    assert pos.tolist() == [i for i, t in enumerate(rows) for _ in want[t]]
    assert members.tolist() == [m for t in rows for m in want[t]]
    assert set(want[0]) == set(range(300))   # the hub's whole fan


def test_welding_groups_positions_by_their_bytes_in_order_of_first_use():
    rng = np.random.default_rng(5)
    pos = rng.integers(-2, 3, (400, 3)).astype(np.float64)
    pos[::17] = [0.0, -0.0, 1.0]       # -0.0 and 0.0 are different bytes: different vertices
    pos[::19] = [0.0, 0.0, 1.0]
    faces = rng.integers(0, 399, (600, 3))   # the last vertex unused
    v, f = tiers._welded(pos, faces)
    # reference: the unique rows of the used vertices, each at its first use
    used = np.unique(faces)
    rows = [pos[i].tobytes() for i in used]
    order = list(dict.fromkeys(rows))
    assert [r.tobytes() for r in v] == order
    assert f.dtype == np.int64
    assert all(v[f[t, c]].tobytes() == pos[faces[t, c]].tobytes() for t in range(600) for c in range(3))


def test_refinement_arrays_made_in_blocks_equal_the_whole_array_formulas(monkeypatch):
    monkeypatch.setattr(tiers, "_BLOCK", 50)
    device = packets.Device() if packets.library() is not None else tiers.new_device()
    ident = Pose(np.eye(3), np.zeros(3))
    V0, F0 = _fan_and_grid()
    items = [(0, Sphere(radius=1.0, subdivision=3), ident), (1, Box(size=(1.0, 2.0, 0.5)), Pose(np.eye(3), np.array([3.0, 0, 0]))),
             (2, Mesh(vertices=V0, faces=F0, closed=False), Pose(np.eye(3), np.array([0, 4.0, 0])))]
    tier = tiers._Tier(device, items, np.array([-1, -1, -1]))
    V, F = tier.V, tier.F
    v0 = V[F[:, 0]]
    e1, e2 = V[F[:, 1]] - v0, V[F[:, 2]] - v0
    nrm = np.cross(e1, e2)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = nrm / np.linalg.norm(nrm, axis=1)[:, None]
        g11, g12, g22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
        inv = 1.0 / (g11 * g22 - g12 * g12)
        inv = np.where(np.isfinite(inv), inv, 0.0)[:, None]
        h = np.linalg.norm(nrm, axis=1) / np.sqrt(np.maximum(np.maximum(g11, g22), _dot(e2 - e1, e2 - e1)))
    want = {"normal": np.vstack([np.nan_to_num(unit), np.zeros((1, 3))]),
            "g1": np.vstack([(g22[:, None] * e1 - g12[:, None] * e2) * inv, np.zeros((1, 3))]),
            "g2": np.vstack([(g11[:, None] * e2 - g12[:, None] * e1) * inv, np.zeros((1, 3))]),
            "h_min": np.where(np.isfinite(h), h, 0.0), "v0": v0, "e1": e1, "e2": e2,
            "t_lo": V[F].min(1), "t_hi": V[F].max(1)}
    for name, w in want.items():
        got = getattr(tier, name)
        assert got.dtype == np.float64 and np.array_equal(got.view(np.int64), w.view(np.int64)), name
    assert tier.ng_max == float(np.linalg.norm(nrm, axis=1).max())


def test_a_soups_risky_edges_are_counted_not_listed():
    n = 500
    F = np.arange(3 * n, dtype=np.int32).reshape(n, 3)   # disjoint triangles: every edge a boundary
    normal = np.tile([0.0, 0.0, 1.0], (n, 1))
    seen = []
    assert risky_edges(F, np.ones(n, dtype=bool), normal, lambda k: seen.append(k) or k > 1000) is None
    assert seen == [3 * n]
    edges, ptr, idx = risky_edges(F, np.ones(n, dtype=bool), normal, lambda k: False)
    assert len(edges) == 3 * n and idx.tolist() == sorted(np.repeat(np.arange(n), 3).tolist())


@pytest.mark.skipif(packets.library() is None, reason=f"packet path unavailable: {packets.status()}")
def test_the_packet_path_shares_the_tiers_arrays_instead_of_copying_them():
    tier = tiers._Tier(packets.Device(), [(0, Box(size=(1.0, 1.0, 1.0)), Pose(np.eye(3), np.zeros(3)))], np.array([-1]))
    scene, _ = tier.scene(True)
    assert scene._shared and scene._shared[0] is tier._v32 and scene._shared[1] is tier.F
    st, _, keep = packets.tier_arrays(tier, True)
    assert any(a is tier.ring.tri_of for a in keep) and any(a is tier.g1 for a in keep)
    with pytest.raises(TypeError, match="packets.c reads"):   # a conversion would be a second copy
        tier._exact["h_min"] = tier._exact["h_min"].astype(np.float32)
        packets.tier_arrays(tier, True)


@pytest.mark.skipif(packets.library() is None, reason=f"packet path unavailable: {packets.status()}")
def test_rays_at_a_high_valence_vertex_get_the_same_bits_in_c_and_numpy():
    """A cone of 64 triangles around one apex (its ring holds the whole cone) and a grid: EXACT rays
    aimed at vertices and edge midpoints are refined through the vertex rings read from each vertex's
    triangles, in packets.c and in numpy alike."""
    from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry

    V, F = _fan_and_grid()
    V = V.copy()
    V[0, 2] = 0.3                                    # the hub raised: a cone, creased edges
    aims = np.tile(np.vstack([V, (V[F[:, 0]] + V[F[:, 1]]) / 2.0, (V[F[:, 1]] + V[F[:, 2]]) / 2.0]), (4, 1))
    rng = np.random.default_rng(7)
    eyes = rng.uniform(-1.0, 1.0, (len(aims), 3)) + [0.0, 0.0, 2.0]
    D = aims + rng.normal(size=aims.shape) * rng.choice([0.0, 1e-9, 1e-7], (len(aims), 1)) - eyes
    D /= np.linalg.norm(D, axis=1)[:, None]
    out = {}
    for native in (False, True):
        eng = RayEngine(Precision.EXACT)
        eng.threads = 1
        eng.native = native
        eng.add_body([ShapeEntry(Mesh(V, F, closed=False), Pose.identity(), True, True)], Pose.identity())
        h = eng.cast(eyes, D, 0.0, 10.0)
        out[native] = (h.distance.tobytes(), h.normal.tobytes(), h.shape.tobytes())
        hit = np.isfinite(h.distance)
    assert out[True] == out[False]
    assert hit.mean() > 0.7


def _torus(k: int = 24) -> Mesh:
    """A closed torus of 2 k² triangles (radii 0.5 and 0.2) about z."""
    u = np.arange(k) * (2.0 * np.pi / k)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    v = np.stack([(0.5 + 0.2 * np.cos(vv)) * np.cos(uu), (0.5 + 0.2 * np.cos(vv)) * np.sin(uu), 0.2 * np.sin(vv)], -1)
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    a, b = (i * k + j).ravel(), (((i + 1) % k) * k + j).ravel()
    c, d = (((i + 1) % k) * k + (j + 1) % k).ravel(), (i * k + (j + 1) % k).ravel()
    return Mesh(v.reshape(-1, 3), np.r_[np.c_[a, b, c], np.c_[a, c, d]], True)


@pytest.mark.parametrize("prec", ["fast", "exact"])
def test_bounding_and_visual_rays_share_one_tier_where_they_see_the_same_shapes(prec):
    """A mesh seen by both kinds of rays (a world's default) is held once, its BVH built once: the
    bounding and the visual tiers of a robot and of the static bodies are one object, and each kind
    still sees exactly what it sees alone; a shape only one kind sees gives each kind its own tier."""
    from sensorium.server.raycast.engine import RayEngine, RayKind, ShapeEntry

    def world(seen_by_both: bool) -> RayEngine:
        eng = RayEngine(prec)
        extra = [] if seen_by_both else [ShapeEntry(Box((0.1, 0.1, 0.1)), Pose(np.eye(3), np.array([0.0, 0, 1])),
                                                    bounding=False, visual=True)]
        eng.add_body([ShapeEntry(_torus(), Pose.identity(), True, True)], Pose(np.eye(3), np.array([3.0, 0, 0])))
        eng.add_body([ShapeEntry(_torus(), Pose.identity(), True, True), *extra], Pose.identity(), owner=0,
                     movable=True)
        return eng

    rng = np.random.default_rng(5)
    a = rng.uniform(-0.4, 0.4, 400) + np.pi * (np.arange(400) % 2)      # towards either torus
    D = np.c_[np.cos(a), np.sin(a), rng.uniform(-0.1, 0.1, 400)]
    D /= np.linalg.norm(D, axis=1)[:, None]
    O = np.broadcast_to([1.5, 0.0, 0.1], D.shape)
    shared = world(True)
    hits = {kind: shared.cast(O, D, 0.0, 10.0, kind=kind) for kind in (RayKind.BOUNDING, RayKind.VISUAL)}
    assert shared.counters["bvh_builds"] == 2            # the static tier and the robot's: once for both kinds
    robot = shared._bodies[1]
    assert robot.tiers["visual"] is robot.tiers["bounding"]
    assert shared._static_tier("visual") is shared._static_tier("bounding")
    for kind, h in hits.items():          # the same bits as an engine casting that kind alone
        alone = world(True).cast(O, D, 0.0, 10.0, kind=kind)
        assert np.isfinite(h.distance).sum() > 300
        assert np.array_equal(h.distance, alone.distance) and np.array_equal(h.shape, alone.shape)
        assert np.array_equal(h.normal, alone.normal)
    apart = world(False)
    for kind in (RayKind.BOUNDING, RayKind.VISUAL):
        apart.cast(O, D, 0.0, 10.0, kind=kind)
    assert apart._bodies[1].tiers["visual"] is not apart._bodies[1].tiers["bounding"]
