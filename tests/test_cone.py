"""Cone (Webots' base node): visual rays against its true surface (EXACT) or its tessellated shell
(FAST), never bounding rays; its .wbt and YAML forms and Webots' texture coordinates."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from sensorium.cli import main as cli
from sensorium.server.raycast import exact
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import texcoords as tc
from sensorium.server.world.geometry import Cone, Pose
from sensorium.server.world.loader import load_world, parse_world

R, HEIGHT, N = 0.4, 1.1, 36
H = HEIGHT / 2.0
ALPHA = math.atan2(R, HEIGHT)                  # half angle at the apex
GAP = R * (1.0 / math.cos(math.pi / N) - 1.0)   # how far the tessellated shell reaches outside (its base ring)
BOTH = [Precision.FAST, Precision.EXACT]
POSE = Pose.from_axis_angle((1.0, 2.0, 0.5), 0.7, (3.0, -1.0, 0.5))   # turned and moved: the frames matter


def _engine(prec: Precision, pose: Pose = POSE) -> RayEngine:
    e = RayEngine(prec)
    e.add_body([ShapeEntry(Cone(R, HEIGHT, N), Pose.identity(), False, True)], pose)
    return e


def _side_normal(phi: np.ndarray) -> np.ndarray:
    return np.c_[np.cos(phi) * math.cos(ALPHA), np.sin(phi) * math.cos(ALPHA), np.full(len(phi), math.sin(ALPHA))]


def _outward(n: np.ndarray, rng, least: float) -> np.ndarray:
    """Unit vectors u with u·n >= least (random), one per row of n."""
    out = np.empty_like(n)
    todo = np.arange(len(n))
    while len(todo):
        u = rng.normal(size=(len(todo), 3))
        u /= np.linalg.norm(u, axis=1)[:, None]
        ok = (u * n[todo]).sum(1) >= least
        out[todo[ok]] = u[ok]
        todo = todo[~ok]
    return out


def _cast(e: RayEngine, points: np.ndarray, u: np.ndarray, dist: np.ndarray, pose: Pose = POSE, kind=RayKind.VISUAL):
    """Rays from points + dist·u toward the points (shape frame), cast in the world."""
    o = pose.apply(points + dist[:, None] * u)
    d = pose.apply_dirs(-u)
    return e.cast(o, d, kind=kind)


@pytest.mark.parametrize("prec", BOTH)
def test_rays_onto_the_slant_surface_hit_it_at_the_closed_form_distance(prec: Precision) -> None:
    rng = np.random.default_rng(3)
    n = 3000
    phi = rng.uniform(0, 2 * math.pi, n)
    z = rng.uniform(-H + 0.01, H - 0.01, n)
    rho = R * (H - z) / HEIGHT
    p = np.c_[rho * np.cos(phi), rho * np.sin(phi), z]
    normal = _side_normal(phi)
    u = _outward(normal, rng, 0.2)
    dist = rng.uniform(0.2, 3.0, n)
    hits = _cast(_engine(prec), p, u, dist)
    assert np.all(np.isfinite(hits.distance)), "a ray missed the cone"
    if prec is Precision.EXACT:
        assert np.abs(hits.distance - dist).max() <= 1e-12
        world_n = POSE.apply_dirs(normal)
        assert np.abs(hits.normal - world_n).max() <= 1e-9
    else:      # the shell lies outside the true surface, at most GAP (plus float32 rounding) from it
        cos_in = (u * normal).sum(1)
        assert np.all(hits.distance <= dist + 2e-6)
        assert np.all(dist - hits.distance <= (GAP + 1e-5) / cos_in)


@pytest.mark.parametrize("prec", BOTH)
def test_the_apex_and_the_base(prec: Precision) -> None:
    """Rays onto the apex from within its normal cone hit the apex; rays from below onto the base
    disc hit it (normal −z); closed form."""
    rng = np.random.default_rng(4)
    n = 500
    e = _engine(prec)
    tilt = rng.uniform(0, 0.5 * (math.pi / 2 - ALPHA), n)
    az = rng.uniform(0, 2 * math.pi, n)
    u = np.c_[np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)]
    dist = rng.uniform(0.1, 2.0, n)
    apex = np.tile([0.0, 0.0, H], (n, 1))
    hits = _cast(e, apex, u, dist)
    bound = 1e-12 if prec is Precision.EXACT else 4.0 * R * 4 / 2 ** 23 + 4e-6 / math.sin(ALPHA)
    assert np.all(np.abs(hits.distance - dist) <= bound)
    ang, rad = rng.uniform(0, 2 * math.pi, n), R * np.sqrt(rng.uniform(0, 0.98, n))
    base = np.c_[rad * np.cos(ang), rad * np.sin(ang), np.full(n, -H)]
    u = _outward(np.tile([0.0, 0.0, -1.0], (n, 1)), rng, 0.3)
    hits = _cast(e, base, u, dist)
    assert np.abs(hits.distance - dist).max() <= (1e-12 if prec is Precision.EXACT else 2e-6 / 0.3 + 1e-5)
    if prec is Precision.EXACT:
        assert np.abs(hits.normal - POSE.apply_dirs([0.0, 0.0, -1.0])).max() <= 1e-12


@pytest.mark.parametrize("prec", BOTH)
def test_a_fan_of_rays_at_the_rim_never_leaks(prec: Precision) -> None:
    """Rays aimed exactly at points of the base's rim, from every direction between the base's
    outward normal and the side's: each meets the cone at the rim (no leak between side and base)."""
    rng = np.random.default_rng(5)
    phi = rng.uniform(0, 2 * math.pi, 400)
    rim = np.c_[R * np.cos(phi), R * np.sin(phi), np.full(len(phi), -H)]
    side = _side_normal(phi)
    down = np.tile([0.0, 0.0, -1.0], (len(phi), 1))
    rows, us = [], []
    for w in np.linspace(0.0, 1.0, 21):           # the fan: from the base's normal to the side's
        u = (1 - w) * down + w * side
        rows.append(rim)
        us.append(u / np.linalg.norm(u, axis=1)[:, None])
    p, u = np.vstack(rows), np.vstack(us)
    dist = rng.uniform(0.3, 2.5, len(p))
    hits = _cast(_engine(prec), p, u, dist)
    assert np.all(np.isfinite(hits.distance)), f"{np.count_nonzero(~np.isfinite(hits.distance))} rays leaked"
    if prec is Precision.EXACT:
        assert np.abs(hits.distance - dist).max() <= 1e-12
    else:
        assert np.all(hits.distance <= dist + 2e-6) and np.all(dist - hits.distance <= (GAP + 1e-5) / 0.05 + 1e-3)


@pytest.mark.parametrize("prec", BOTH)
def test_rays_from_inside_meet_the_true_surface(prec: Precision) -> None:
    """A ray starting inside the cone (the curved-shell pre-pass) hits the inside of its surface."""
    e = _engine(prec, Pose.identity())
    phi = np.linspace(0, 2 * math.pi, 24, endpoint=False)
    d = np.c_[np.cos(phi), np.sin(phi), np.zeros(24)]
    hits = e.cast(np.zeros((24, 3)), d, kind=RayKind.VISUAL)
    assert np.abs(hits.distance - R / 2).max() <= (1e-12 if prec is Precision.EXACT else GAP + 1e-5)
    down = e.cast(np.zeros((1, 3)), np.array([[0.0, 0.0, -1.0]]), kind=RayKind.VISUAL)
    assert abs(down.distance[0] - H) <= 1e-12


def test_bounding_rays_never_see_a_cone() -> None:
    e = _engine(Precision.EXACT)
    o = POSE.apply(np.array([[0.0, 0.0, 3.0]]))
    d = POSE.apply_dirs(np.array([[0.0, 0.0, -1.0]]))
    assert math.isinf(e.cast(o, d, kind=RayKind.BOUNDING).distance[0])
    assert abs(e.cast(o, d, kind=RayKind.VISUAL).distance[0] - (3.0 - H)) <= 1e-12


def test_the_scalar_twin_gives_the_same_bits() -> None:
    """exact._analytic_one (a few rays, Python floats) and _analytic_local (numpy) agree bit for bit,
    also for rays parallel to a generating line and through the apex."""
    rng = np.random.default_rng(6)
    n = 2000
    p = rng.uniform(-1.5, 1.5, (n, 3))
    d = rng.uniform([-R, -R, -H], [R, R, H], (n, 3)) - p      # toward the cone's box: many hits
    d /= np.linalg.norm(d, axis=1)[:, None]
    k = R / HEIGHT
    d[:50] = np.c_[np.full(50, k), np.zeros(50), np.full(50, -1.0)] / math.hypot(k, 1.0)   # along a generator
    p[:50, 2] = rng.uniform(-1, 1, 50)
    p[50:60] = [0.0, 0.0, H + 1.0]
    d[50:60] = [0.0, 0.0, -1.0]
    lo, hi = np.full(n, 1e-9), np.full(n, np.inf)
    t, nrm = exact._analytic_local(exact._CONE, p, d, R, H, lo, hi)
    assert np.count_nonzero(np.isfinite(t)) > 300
    assert t[50] == 1.0 and nrm[50].tolist() == [0.0, 0.0, 1.0]        # the apex
    for i in range(n):
        ti, ni = exact._analytic_one(exact._CONE, tuple(p[i]), tuple(d[i]), R, H, 1e-9, math.inf)
        assert ti == t[i] or (math.isinf(ti) and math.isinf(t[i])), i
        if math.isfinite(ti):
            assert list(ni) == nrm[i].tolist() or np.array_equal(np.abs(ni), np.abs(nrm[i])), i
    # per-ray sizes (the kind-by-kind pass of several cones) give the same bits as scalar sizes
    t2, _ = exact._analytic_local(exact._CONE, p, d, np.full(n, R), np.full(n, H), lo, hi)
    assert np.array_equal(t, t2)


def test_texture_coordinates_are_webots_picking() -> None:
    """WbCone::pickUVCoordinate: side u = (atan2(x, −y) + π)/2π off the axes (Webots' own values on
    them), v = 1 − (z + h/2)/h; base u = (x + r)/2r, v = 1 − (r − y)/2r; set 1 halves u."""
    r, h = 1.0, 2.0
    z = 0.0
    rho = r * (h / 2 - z) / h
    pts, want = [], []
    for phi in (0.3, 1.9, 3.5, 5.1):
        x, y = rho * math.cos(phi), rho * math.sin(phi)
        pts.append((x, y, z))
        want.append(((math.atan2(x, -y) + math.pi) / (2 * math.pi), 0.5))
    pts += [(rho, 0.0, z), (0.0, -rho, z), (0.3, -0.2, -1.0)]
    want += [(0.75, 0.5), (0.0, 0.5), ((0.3 + 1) / 2, 1 - (0.2 + 1) / 2)]   # Webots' atan(x/−y) on the axes
    uv = tc.cone_uv(np.array(pts), r, h)
    assert np.abs(uv - np.array(want)).max() <= 1e-15
    atlas = tc.cone_uv(np.array(pts), r, h, atlas=True)
    assert np.abs(atlas[:, 0] - np.where(np.arange(7) < 6, uv[:, 0] * 0.5, uv[:, 0] * 0.5 + 0.5)).max() <= 1e-15
    shell = tc.cone_uv(np.array([[0.0, -rho * 1.001, z]]) + [1e-9, 0, 0], r, h)   # a FAST point off the side
    assert abs(shell[0, 1] - 0.5) < 1e-3


HEADER = "#VRML_SIM R2023b utf8\n"


def test_wbt_cones_are_visual_and_never_bounding(tmp_path: Path, capsys) -> None:
    """A Shape's Cone loads (validate exits 0); the same Cone as a boundingObject is left out with
    one line (Webots accepts none there), not a loss; an infra-red sensor sees it, a generic one not."""
    p = tmp_path / "c.wbt"
    p.write_text(HEADER + 'Solid {\n  translation 0.5 0 0\n  children [ Shape { geometry DEF C Cone { bottomRadius 0.2 '
                 'height 0.4 } } ]\n  boundingObject USE C\n}\n'
                 'Robot { name "bot" children [\n'
                 '  DistanceSensor { name "ir" type "infra-red" lookupTable [ 0 0 0 1 1000 0 ] }\n'
                 '  DistanceSensor { name "gen" lookupTable [ 0 0 0 1 1000 0 ] } ] }\n')
    w = load_world(p)
    assert not w.losses
    (shape,) = w.world.solids[0].shapes
    assert shape.geometry.type == "cone" and (shape.geometry.bottom_radius, shape.geometry.height) == (0.2, 0.4)
    said = [x for x in w.warnings if "Cone in a boundingObject" in x]
    assert len(said) == 1 and said[0].startswith(f"{p}:4:")        # the Cone's line (USEd on line 5)
    assert cli(["validate", str(p)]) == 0
    capsys.readouterr()
    sim = Simulation(w, precision="exact")
    for dev in sim.all_devices():
        dev.enable(sim.basic_time_step)
    sim.step()
    assert sim.device("bot/ir").value == pytest.approx(1000 * (0.5 - 0.1), abs=1e-9)   # the side at z = 0
    assert sim.device("bot/gen").value == pytest.approx(1000.0)                        # nothing: max range


def test_yaml_cone_and_its_errors(tmp_path: Path, capsys) -> None:
    w = parse_world({"solids": [{"name": "c", "geometry": {"type": "cone", "bottom_radius": 0.3, "height": 0.5}}]})
    assert w.world.solids[0].geometry.subdivision == 36
    for bad, what in (({"bottom_radius": 0}, "bottom_radius"), ({"height": -1}, "height")):
        f = tmp_path / "c.yaml"
        f.write_text(yaml.safe_dump({"solids": [{"name": "c", "geometry": {"type": "cone", **bad}}]}))
        assert cli(["validate", str(f)]) == 1
        assert f"solids[0] (c).geometry.{what}" in capsys.readouterr().err
    f.write_text(yaml.safe_dump({"solids": [{"name": "c", "seen_by": "bounding", "geometry": {"type": "cone"}}]}))
    assert cli(["validate", str(f)]) == 1
    assert "a cone is seen by visual rays only" in capsys.readouterr().err


def test_a_world_with_a_cone_batched_is_the_single_simulation() -> None:
    """A solid holding a cone gets its own tier (numpy-judged); the batched copies of a world with one
    still read what the single simulation reads, bit for bit (its lidar sees the cone)."""
    from sensorium.schemas import world as wm
    from sensorium.server.sim.batched import BatchedSimulation
    from sensorium.server.world.loader import LoadedWorld, default_world_path

    lw = load_world(default_world_path())
    cone = wm.Solid(name="cone", pose=wm.Pose(translation=(0.3, 0.3, 0.2)),
                    geometry=wm.Cone(type="cone", bottom_radius=0.1, height=0.4))
    worlds = [lw.world.model_copy(update={"solids": [*lw.world.solids, cone], "world_info": lw.world.world_info
                                          .model_copy(update={"random_seed": s})}) for s in (1, 2)]
    for prec in ("fast", "exact"):
        bs = BatchedSimulation(LoadedWorld(world=worlds[0], source=lw.source, base_dir=lw.base_dir), 2, precision=prec)
        bs.reset(np.arange(2), [1, 2])
        sims = [Simulation(LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir), precision=prec) for w in worlds]
        for name in ("lidar", "sonar_front"):
            bs.enable(bs.device("scout", name), 32)
            for s in sims:
                s.robot("scout").device(name).enable(32)
        for _ in range(4):
            bs.step()
            for s in sims:
                s.step()
        for c, s in enumerate(sims):
            single = np.asarray(s.robot("scout").device("lidar").range_image).ravel()
            assert np.array_equal(single, np.asarray(bs.range_image(bs.device("scout", "lidar"))[c]).ravel())
        hits = sims[0].scene.engine.cast(np.array([[0.0, 0.0, 0.2]]), np.array([[1.0, 1.0, 0.0]]) / math.sqrt(2),
                                         kind=RayKind.VISUAL)
        assert sims[0].scene.shapes[int(hits.shape[0])].name == "cone"
