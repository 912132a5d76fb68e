"""Packet traversal (sensorium/server/raycast/packets.py) and ray blocks on several threads
(blocks.py): the same answers as embreex's one-ray-per-call loop and as one thread, bit for bit;
without a compiler or with the path switched off, the engine falls back to embreex and says why."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from sensorium.server.raycast import blocks, packets
from sensorium.server.raycast.engine import Mount, Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Mesh, Plane, Pose, Sphere, tessellate

needs_packets = pytest.mark.skipif(packets.library() is None, reason=f"no packet path here: {packets.status()}")


def _rz(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _soup():
    """Boxes, a tessellated sphere and an open square: (vertices, faces) and the points rays aim at
    (vertices, edge midpoints, triangle centres: where traversal ties and watertightness matter)."""
    vs, fs, k = [], [], 0
    for prim, at in ((Box((1.0, 0.6, 0.8)), (1.5, 0.2, 0.4)), (Box((0.3, 2.0, 1.5)), (-1.2, -0.4, 0.75)),
                     (Sphere(0.4, subdivision=2), (0.2, -1.4, 0.6))):
        v, f = tessellate(prim)
        vs.append(v + at)
        fs.append(np.asarray(f) + k)
        k += len(v)
    V, F = np.vstack(vs), np.vstack(fs)
    e = trimesh.Trimesh(V, F, process=False).edges_unique
    aims = np.vstack([V, (V[e[:, 0]] + V[e[:, 1]]) / 2, V[F].mean(axis=1)])
    return V, F, aims


def _rays(aims, eye, jitter, rng):
    d = aims + rng.normal(size=aims.shape) * jitter - eye
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.broadcast_to(np.asarray(eye, dtype=np.float64), d.shape), d


@needs_packets
@pytest.mark.parametrize("robust", [False, True])
def test_packets_give_embreex_answers_bit_for_bit(robust):
    """rtcIntersect16 (incoherent packets: what EXACT and scattered sensor rays use) and embreex's
    rtcIntersect1 loop on the same library, scene and float32 rays: the same distance, triangle,
    geometry, barycentrics and normal for every ray, including rays aimed exactly at vertices and
    edges; misses come back as misses. Coherent packets (a FAST lidar scan) differ only for rays
    aimed within float32 rounding of an edge or a vertex: the neighbouring triangle of the same
    surface (within 32 float32 ulps) or, in a plain scene, the other side of the edge."""
    from embreex import rtcore as rtc
    from embreex import rtcore_scene as rts
    from embreex.mesh_construction import TriangleMesh

    V, F, aims = _soup()
    at_edge = np.arange(len(aims)) < len(aims) - len(F)      # vertices and edge midpoints (not centres)
    V32, F32 = V.astype(np.float32), F.astype(np.int32)
    gv, gf = tessellate(Box((0.1, 0.1, 3.0)))              # a second geometry (as EXACT's guards are)
    gv = (gv + [0.0, 1.0, 1.5]).astype(np.float32)
    ref = rts.EmbreeScene(rtc.EmbreeDevice(), robust=robust)
    TriangleMesh(ref, V32, F32)
    TriangleMesh(ref, gv, np.asarray(gf, dtype=np.int32))
    dev = packets.Device()
    scene = packets.Scene(dev, robust, V32, F32, gv, gf)
    rng = np.random.default_rng(1)
    second, differ, total = False, 0, 0
    for eye in ([0.3, 0.1, 2.5], [-3.0, 2.5, 0.4], [0.0, 0.0, 0.5]):
        for jitter in (0.0, 1e-7, 1e-3):
            O, D = _rays(aims, eye, jitter, rng)
            o32, d32 = np.ascontiguousarray(O, dtype=np.float32), D.astype(np.float32)
            far = np.full(len(D), 20.0, dtype=np.float32)
            far[::7] = 1.0                                     # some rays stop short
            want = ref.run(o32, d32, far.copy(), output=1)
            hit = want["primID"] >= 0
            assert hit.sum() > len(D) // 3 and (~hit).sum() > 0
            got = scene.run(np.broadcast_to(o32[:1], o32.shape), d32, far, output=1)
            for key in ("tfar", "primID", "geomID"):
                assert got[key].tobytes() == want[key].tobytes(), key
            for key in ("u", "v", "Ng"):
                assert got[key][hit].tobytes() == want[key][hit].tobytes(), key
            second |= bool((got["geomID"] == 1).any())
            assert np.array_equal(far[::7], np.ones(len(far[::7]), np.float32))   # the limits are not written
            coh = scene.run(np.broadcast_to(o32[:1], o32.shape), d32, far, output=1, coherent=True)
            bad = (coh["tfar"] != want["tfar"]) | (coh["primID"] != want["primID"])
            differ += int(bad.sum())
            total += len(D)
            assert not bad[~at_edge].any()                      # only rays aimed at an edge or a vertex
            if robust:   # watertight: the same surface, within 32 float32 ulps
                both = bad & hit & (coh["primID"] >= 0)
                ulp = np.spacing(want["tfar"][both])
                assert np.all(np.abs(coh["tfar"][both] - want["tfar"][both]) <= 32 * ulp)
            if jitter == 1e-3:
                assert not bad.any()                            # clear of edges: the same answers
    assert second                                               # the second geometry was hit too
    assert differ <= 0.02 * total


def _scene(precision):
    """Flat and curved solids, a floor, a mesh, a moving robot with a body and two others."""
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    for prim, at in ((Box((0.5, 0.4, 1.0)), (1.5, 0.3, 0.5)), (Sphere(0.4), (-1.2, 0.8, 0.4)),
                     (Cylinder(0.2, 1.5), (0.4, -1.4, 0.75)), (Capsule(0.15, 0.8), (-0.6, -0.9, 0.6)),
                     (Box((6.0, 0.1, 2.0)), (0.0, 3.0, 1.0))):
        eng.add_body([ShapeEntry(prim, Pose.identity(), True, True)], Pose(_rz(0.3), np.array(at)))
    rock = trimesh.creation.icosphere(subdivisions=1, radius=0.3)
    eng.add_body([ShapeEntry(Mesh(rock.vertices, rock.faces, closed=True), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([2.0, -2.0, 0.3])))
    robot = eng.add_body([ShapeEntry(Box((0.3, 0.2, 0.12)), Pose.identity(), True, True)],
                         Pose(_rz(0.5), np.array([0.1, 0.2, 0.06])), owner=0, movable=True)
    for k, at in enumerate([(0.8, -0.2), (-0.7, 0.1)]):
        eng.add_body([ShapeEntry(Cylinder(0.05, 0.1), Pose.identity(), True, True)],
                     Pose(np.eye(3), np.array([*at, 0.05])), owner=k + 1, movable=True)
    return eng, robot


def _lidar(W=512, L=48):
    az = np.linspace(-math.pi, math.pi, W, endpoint=False)
    el = np.linspace(-0.4, 0.3, L)
    A, E = np.meshgrid(az, el)
    return np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)


@pytest.mark.parametrize("precision", [Precision.FAST, Precision.EXACT])
def test_paths_and_threads_give_the_same_answers(precision, monkeypatch):
    """One engine on embreex's path, one on the packet path with 1 thread, one with 2 threads (a
    24,576-ray batch: split in blocks), one with 4 threads and tiny blocks: every distance, normal
    and shape id is the same bit for bit -- a lidar mounted on a robot with a body (Mount(own=True)),
    and scattered rays with per-ray limits and exclusions."""
    from sensorium.server.raycast import engine as engine_module

    engines = {}
    with monkeypatch.context() as m:
        m.setattr(packets, "library", lambda: None)
        engines["embreex"] = _scene(precision)
    for name, threads in (("packets", 1), ("2 threads", 2), ("4 threads", 4)):
        engines[name] = _scene(precision)
        engines[name][0].threads = threads
    rng = np.random.default_rng(3)
    D_loc = _lidar()
    assert len(D_loc) >= blocks.MIN_RAYS
    O_many = rng.uniform(-2.5, 2.5, (len(D_loc), 3)) * [1, 1, 0.3] + [0, 0, 0.5]
    D_many = rng.normal(size=O_many.shape)
    D_many /= np.linalg.norm(D_many, axis=1)[:, None]
    far = rng.uniform(0.5, 6.0, len(D_many))
    excl = rng.choice([-1, 0, 1], len(D_many))
    results = {}
    for name, (eng, robot) in engines.items():
        if name == "4 threads":
            monkeypatch.setattr(engine_module, "_CHUNK", 1000)
        mount = Mount(np.full(len(D_loc), robot), own=True)
        out = []
        for step in range(3):
            pose = Pose(_rz(0.5 + 0.4 * step), np.array([0.1 + 0.1 * step, 0.2, 0.06]))
            eng.set_body_pose(robot, pose)
            O = np.broadcast_to(pose.apply(np.array([[0.0, 0.0, 0.09]]))[0], D_loc.shape)
            D = D_loc @ pose.rotation.T
            out.append(eng.cast(O, D, 0.02, 6.0, kind=RayKind.VISUAL, mount=mount, distance_only=True).distance)
            h = eng.cast(O_many, D_many, 0.0, far, kind=RayKind.BOUNDING, exclude_owner=excl)
            out += [h.distance, h.normal, h.shape]
        results[name] = out
        monkeypatch.setattr(engine_module, "_CHUNK", 1 << 16)
    base = results["embreex"]
    assert np.isfinite(base[0]).mean() > 0.5 and np.isfinite(base[1]).mean() > 0.3
    for name, out in results.items():
        for a, b in zip(base, out):
            assert a.tobytes() == b.tobytes(), name


def test_blocks_split_cover_the_batch_and_run_keeps_order():
    for n, threads, chunk in ((10, 2, 65536), (20000, 2, 65536), (131072, 2, 65536), (1_000_003, 3, 65536),
                              (5000, 1, 1000)):
        parts = blocks.split(n, threads, chunk)
        assert parts[0].start == 0 and parts[-1].stop == n
        assert all(a.stop == b.start for a, b in zip(parts, parts[1:]))
        assert all(p.stop - p.start <= chunk for p in parts)
        if threads > 1 and n >= blocks.MIN_RAYS:
            assert len(parts) >= threads and len(parts) % threads == 0
        if n < blocks.MIN_RAYS and n <= chunk:
            assert len(parts) == 1                    # small batches stay whole, on one thread
    out = blocks.run(lambda k: k * k, list(range(50)), 3)
    assert out == [k * k for k in range(50)]
    with pytest.raises(ZeroDivisionError):
        blocks.run(lambda k: 1 // (k - 7), list(range(20)), 2)
    # a block that splits again runs its parts on its own thread (no waiting on the pool)
    assert blocks.run(lambda k: sum(blocks.run(lambda j: j, list(range(k)), 2)), [3, 4, 5], 2) == [3, 6, 10]


@pytest.mark.parametrize("threads", [1, 2])
def test_blocks_run_does_first_work_on_the_calling_thread_beside_the_blocks(threads):
    """``first`` runs once, on the calling thread, before it takes a block; blocks that need its
    result wait for it (the engine lists a Mount's pairs so); its exception is raised after the
    blocks taken are done, and blocks that wait for it are not left hanging."""
    import threading

    ready, seen = threading.Event(), {}

    def first():
        seen["thread"] = threading.current_thread()
        seen["value"] = 10
        ready.set()

    def block(k):
        ready.wait(timeout=30)
        return k + seen["value"]

    assert blocks.run(block, list(range(6)), threads, first) == [k + 10 for k in range(6)]
    assert seen["thread"] is threading.current_thread()

    ready2 = threading.Event()

    def failing():
        try:
            raise KeyError("first failed")
        finally:
            ready2.set()

    with pytest.raises(KeyError, match="first failed"):
        blocks.run(lambda k: ready2.wait(timeout=30) and k, list(range(6)), threads, failing)


def test_without_a_compiler_or_switched_off_the_engine_uses_embreex_and_says_why(monkeypatch, tmp_path):
    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.setenv("SENSORIUM_PACKETS", "0")
    assert packets.library() is None and "SENSORIUM_PACKETS=0" in packets.status()
    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.delenv("SENSORIUM_PACKETS")
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    monkeypatch.setenv("SENSORIUM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(packets.tempfile, "gettempdir", lambda: str(tmp_path / "tmp"))
    assert packets.library() is None
    assert packets.status().startswith("embreex, one ray per call (compiling packets.c failed")
    eng = RayEngine(Precision.FAST)                      # still casts, through embreex
    eng.add_body([ShapeEntry(Box((1.0, 1.0, 1.0)), Pose.identity(), True, True)], Pose.identity())
    assert eng.cast(np.array([[0.0, 0.0, 3.0]]), np.array([[0.0, 0.0, -1.0]])).distance[0] == pytest.approx(2.5)


@needs_packets
def test_a_helper_built_beforehand_is_used_without_a_compiler_on_another_kernel(monkeypatch, tmp_path):
    """What the Docker image does: packets.c compiled at image build into SENSORIUM_CACHE_DIR; the
    containers (no compiler, maybe another kernel) load that library."""
    monkeypatch.setenv("SENSORIUM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(packets.tempfile, "gettempdir", lambda: str(tmp_path / "tmp"))
    monkeypatch.setattr(packets, "_state", {})
    assert packets.library() is not None                         # built here, into the cache
    built = sorted((tmp_path / "cache").glob("packets-*.so"))
    assert [p.name for p in built] == [f"packets-{packets.build_key()}.so"]
    monkeypatch.setattr(packets, "_state", {})
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    monkeypatch.setattr(packets.platform, "platform", lambda *a, **k: "Linux-9.9.9-other-kernel-x86_64")
    monkeypatch.setattr(packets.platform, "release", lambda: "9.9.9-other-kernel")
    assert packets.library() is not None and packets.status().startswith("Embree packets of 16")
    assert sorted((tmp_path / "cache").glob("packets-*.so")) == built   # found, not rebuilt


@needs_packets
def test_box3_is_numpys_column_min_and_max():
    rng = np.random.default_rng(5)
    for n in (1, 2, 17, 23040):
        O = rng.normal(size=(n, 3)) * rng.choice([1e-3, 1.0, 1e5], size=(n, 1))
        lo, hi = packets.box3(O)
        assert lo.tolist() == [O[:, k].min() for k in range(3)] and hi.tolist() == [O[:, k].max() for k in range(3)]
    O = rng.normal(size=(50, 3))
    O[7, 1], O[30, 2], O[3, 0] = np.nan, -np.inf, np.inf      # NaN propagates as numpy's min/max does
    lo, hi = packets.box3(O)
    assert np.isnan(lo[1]) and np.isnan(hi[1]) and lo[2] == -np.inf and hi[0] == np.inf
    assert lo[0] == O[:, 0].min() and hi[2] == O[:, 2].max()
    # arrays it does not read: None (the caller's numpy path)
    assert packets.box3(np.asfortranarray(O)) is None and packets.box3(O.astype(np.float32)) is None
    assert packets.box3(np.zeros((0, 3))) is None


@pytest.mark.parametrize("variant", ["bounding", "visual"])
@pytest.mark.parametrize("floor", ["up", "ceiling", "sized", "owned"])
def test_one_floor_in_c_is_the_numpy_plane_pass_bit_for_bit(variant, floor):
    """planes.cast_planes for one axis-aligned plane: packets.plane1 (one C pass; the engine's
    default) gives the numpy pass's distances, shapes and normals bit for bit (signed zeros of the
    flipped normals included) -- two-sided and one-sided, a ceiling (normal -z, times -1), a sized
    plane, an owned plane with per-ray and scalar excluded owners; scattered and one-origin rays,
    per-ray and scalar limits, NaN and horizontal directions, rays from on the plane -- and None
    exactly when numpy's is; and meets closed-form distances."""
    from sensorium.server.raycast import planes as planes_module

    if packets.library() is None:
        pytest.skip(packets.status())
    flip = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
    pose = {"up": Pose(np.eye(3), np.array([0.0, 0.0, 0.1])), "ceiling": Pose(flip, np.array([0.0, 0.0, 2.0])),
            "sized": Pose.identity(), "owned": Pose(np.eye(3), np.array([0.0, 0.0, -0.3]))}[floor]
    eng = RayEngine(Precision.FAST)
    eng.add_body([ShapeEntry(Box((0.2, 0.2, 0.2)), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Plane((3.0, 2.0) if floor == "sized" else None), Pose.identity(), True, True)], pose,
                 owner=4 if floor == "owned" else -1)
    rng = np.random.default_rng({"up": 1, "ceiling": 2, "sized": 3, "owned": 4}[floor])
    n = 3000
    O = rng.uniform(-2.0, 2.0, (n, 3))
    O[::9, 2] = pose.translation[2]                # on the plane
    D = rng.normal(size=(n, 3))
    D /= np.linalg.norm(D, axis=1)[:, None]
    D[::7, 2] = 0.0                                 # parallel to it
    D[5::101] = np.nan
    eng.cast(O[:1], D[:1], kind=RayKind(variant == "visual"))   # builds and refreshes the plane data
    pl = eng._plane_set(variant)
    assert pl is not None and pl.axis == 2
    one = np.broadcast_to(O[3], O.shape)
    cases = [(O, 0.0, np.inf, -1), (O, 0.05, 3.0, 4), (one, 0.0, rng.uniform(0.0, 4.0, n), -1),
             (O, rng.uniform(0.0, 0.5, n), rng.uniform(0.5, 4.0, n), rng.integers(2, 6, n)), (one, 0.0, 0.01, 4)]
    seen = 0
    for O_, t_near, t_far, excl in cases:
        for distance_only in (False, True):
            with np.errstate(divide="ignore", invalid="ignore"):
                want = planes_module.cast_planes(pl, eng._epoch, O_, D, t_near, t_far, excl, 1e-9, distance_only)
                got = planes_module.cast_planes(pl, eng._epoch, O_, D, t_near, t_far, excl, 1e-9, distance_only,
                                                native=True)
            if want is None or (distance_only and O_ is one and variant == "visual"):
                assert (got is None) == (want is None)   # (the lean one-origin path is numpy's on both)
                if want is None:
                    continue
            seen += 1
            assert got[0].tobytes() == want[0].tobytes()
            if distance_only:
                assert got[1] is None and got[2] is None
            else:
                assert got[1].tobytes() == want[1].tobytes() and got[2].tobytes() == want[2].tobytes()
    assert seen >= 6
    # closed form: straight down (and up) onto the plane from 1 m on its front side
    z0 = float(pose.translation[2])
    side = -1.0 if floor == "ceiling" else 1.0
    Oc = np.array([[0.5, 0.5, z0 + side], [0.5, 0.5, z0 + side]])
    Dc = np.array([[0.0, 0.0, -side], [0.0, 0.0, side]])
    got = planes_module.cast_planes(pl, eng._epoch, Oc, Dc, 0.0, np.inf, -1, 1e-9, False, native=True)
    assert got[0][0] == 1.0 and got[0][1] == np.inf
    assert got[2][0].tolist() == [0.0, 0.0, side] and got[1][1] == -1


def test_a_large_fast_cast_is_split_over_threads_inside_the_c_pass(monkeypatch):
    """A FAST cast of >= MIN_RAYS rays through the packet path is one C call that traces parts of
    the batch on `threads` POSIX threads (no Python blocks around it): 16,421 rays (not a whole
    number of packets), many origins and one origin, with normals and without, give the same bits
    on 1, 2, 3 and 5 threads, and the call asked for them."""
    if packets.library() is None:
        pytest.skip(f"packet path off: {packets.status()}")
    lib = packets.library()
    asked: list[tuple[int, int]] = []
    real = lib.sp_fast_pass

    def spy(*args):
        asked.append((args[2], args[-3]))      # (rays, threads; then run and seg_end)
        return real(*args)

    monkeypatch.setattr(lib, "sp_fast_pass", spy)
    rng = np.random.default_rng(11)
    n = blocks.MIN_RAYS + 37
    D = rng.normal(size=(n, 3))
    D /= np.linalg.norm(D, axis=1)[:, None]
    O_many = rng.uniform(-2.5, 2.5, (n, 3)) * [1, 1, 0.3] + [0, 0, 0.5]
    O_one = np.broadcast_to(np.array([0.2, -0.1, 0.4]), (n, 3))
    D_wall = D * [0.2, 0.0, 0.2] + [0.0, 1.0, 0.0]      # toward the long wall at y = 3: most rays hit it
    D_wall /= np.linalg.norm(D_wall, axis=1)[:, None]
    D_wall[::4] = D[::4]                                  # and a quarter anywhere: some miss
    O_wall = np.broadcast_to(np.array([0.0, 2.0, 1.0]), (n, 3))
    results = {}
    for threads in (1, 2, 3, 5):
        eng, _ = _scene(Precision.FAST)
        eng.threads = threads
        asked.clear()
        out = []
        for O, DD in ((O_many, D), (O_one, D), (O_wall, D_wall)):
            h = eng.cast(O, DD, 0.0, 6.0, kind=RayKind.VISUAL)
            out += [h.distance, h.normal, h.shape]
            out.append(eng.cast(O, DD, 0.0, 6.0, kind=RayKind.VISUAL, distance_only=True).distance)
        assert [t for m, t in asked if m == n] == [threads] * 6   # the static tier's passes: one call each
        results[threads] = out
    assert np.isfinite(results[1][0]).mean() > 0.3
    assert 0.5 < np.isfinite(results[1][8]).mean() < 1.0     # most hit (the C pass's whole-array judging)
    for threads, out in results.items():
        for a, b in zip(results[1], out):
            assert a.tobytes() == b.tobytes(), threads


def test_work_inside_a_block_knows_it_is_in_a_block():
    """A block's work (on a pool worker or on run()'s calling thread) sees in_block(), so a FAST
    pass inside it traces on that thread alone (no threads of its own beside the blocks); outside
    run() it does not."""
    assert not blocks.in_block()
    seen = blocks.run(lambda k: blocks.in_block(), list(range(6)), 2)
    assert seen == [True] * 6
    assert not blocks.in_block()


@needs_packets
def test_atan2_in_c_is_math_atan2_bit_for_bit():
    """packets.atan2 (the vector env's poses' yaw) gives math.atan2 of every pair, bit for bit:
    random angles' cos/sin (the rotation entries it reads), signed zeros, infinities, NaN, tiny
    and huge values; strided views in and out; closed form atan2(1, 1) = pi / 4."""
    rng = np.random.default_rng(3)
    a = rng.uniform(-math.pi, math.pi, 4000)
    special = [0.0, -0.0, 1.0, -1.0, math.inf, -math.inf, math.nan, 1e-310, -1e-310, 1e300]
    ys = np.concatenate([np.sin(a), np.repeat(special, len(special))])
    xs = np.concatenate([np.cos(a), np.tile(special, len(special))])
    rot = np.zeros((len(ys), 3, 3))
    rot[:, 1, 0], rot[:, 0, 0] = ys, xs
    out = np.zeros((len(ys), 3))
    got = packets.atan2(rot[:, 1, 0], rot[:, 0, 0], out[:, 2])
    want = np.array([math.atan2(y, x) for y, x in zip(ys.tolist(), xs.tolist())])
    assert got is not None and got.base is out
    assert out[:, 2].tobytes() == want.tobytes() and not out[:, :2].any()
    assert packets.atan2(np.ones(1), np.ones(1))[0] == math.pi / 4
    assert packets.atan2(np.ones(2, dtype=np.float32), np.ones(2, dtype=np.float32)) is None


@needs_packets
@pytest.mark.parametrize("base, landmark", [((0.0, 0.0, 0.0), False), ((1e4, 5e3, 0.0), False),
                                            ((1e4, 5e3, 0.0), True), ((1e6, -7e5, 3e2), True)],
                         ids=["origin", "far", "far-coarse-frame", "1e6-coarse-frame"])
@pytest.mark.parametrize("draws", [1, pytest.param(2, marks=pytest.mark.slow)])   # (2: a second draw, same engines)
def test_exact_on_adversarial_edge_rays_is_embreexs_on_both_paths(base, landmark, draws, monkeypatch):
    """EXACT through the packet path (incoherent packets, judged in C) and through embreex (one ray
    per call, judged in numpy), on test_exact_guards.py's rays aimed at shared edges, box edges,
    corners, a seam and an open mesh's boundary, nudged by 0 to 1e-5 m, near and far from the
    origin: every distance, normal and shape the same bit for bit. (Where two triangles meet at
    the same float32 distance, EXACT's answer is the float64 plane of the one Embree reports: the
    traversal must be embreex's, which is why EXACT never traces coherent packets.)"""
    from tests.test_exact_guards import _engine, _rays

    base = np.array(base)
    rays = [_rays(s) for s in range(1, draws + 1)]
    with monkeypatch.context() as m:
        m.setattr(packets, "library", lambda: None)
        ref = _engine(base, landmark)
        want = [ref.cast(O + base, D) for O, D in rays]
    eng = _engine(base, landmark)
    for (O, D), w in zip(rays, want):
        got = eng.cast(O + base, D)
        assert got.distance.tobytes() == w.distance.tobytes()
        assert got.normal.tobytes() == w.normal.tobytes() and got.shape.tobytes() == w.shape.tobytes()
        assert np.isfinite(w.distance).mean() > 0.5
    assert eng.counters["embree_calls"] > 0 and ref.counters["embree_calls"] > 0


@needs_packets
def test_devices_of_uncollected_simulations_are_freed_when_embree_runs_out() -> None:
    """Found: Debian's Embree 3 refuses a new device after about 1,000 live ones in a process, and engines no
    longer used but held in reference cycles (as a Simulation's are) keep theirs until the cycle collector
    runs, so a loop building simulations could fail with "rtcNewDevice failed". A refused device now has the
    garbage collected and is asked for once more."""
    import gc

    class Held:           # a device in a reference cycle: freed only by the cycle collector
        def __init__(self) -> None:
            self.me, self.device = self, packets.Device()

    was = gc.isenabled()
    gc.disable()
    try:
        for _ in range(1200):   # more than Embree 3 holds at once: every one unreachable but uncollected
            Held()
        assert packets.Device().handle
    finally:
        if was:
            gc.enable()
        gc.collect()
