"""ElevationGrid (Webots' height field): its triangles, rays against them in closed form, .wbt and
YAML worlds that use it, its limits and its texture coordinates."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.cli import main as cli
from sensorium.schemas import world as wm
from sensorium.server.devices import lidar as lmath
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.sim import contact
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import texcoords as tc
from sensorium.server.world.geometry import Pose, Terrain, elevation_grid
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.meshes import elevation_grid_mesh

BOTH = [Precision.FAST, Precision.EXACT]
BOUND = {Precision.EXACT: 1e-12, Precision.FAST: 2e-6}
HEADER = "#VRML_SIM R2023b utf8\n"


def _engine(prec: Precision, mesh: Terrain, at=(0.0, 0.0, 0.0), visual: bool = True) -> RayEngine:
    e = RayEngine(prec)
    e.add_body([ShapeEntry(mesh, Pose.identity(), True, visual)], Pose.from_axis_angle((0, 0, 1), 0.0, at))
    return e


def test_grid_points_and_the_diagonal_webots_renders() -> None:
    """Point (i, j) at (i·dx, j·dy, height[j·nx + i]); each cell split from (i, j) to (i+1, j+1)."""
    v, f = elevation_grid(range(6), 3, 0.5, 2, 2.0)
    assert v.tolist() == [[0, 0, 0], [0.5, 0, 1], [1, 0, 2], [0, 2, 3], [0.5, 2, 4], [1, 2, 5]]
    assert f.tolist() == [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]
    tri = v[f]
    normal_z = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2]
    assert np.all(normal_z > 0)                      # counter-clockwise seen from +z
    with pytest.raises(ValueError):
        elevation_grid([0, 0, 0], 2, 1.0, 2, 1.0)    # 3 heights for 4 points


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("offset", [0.0, 1e5])
def test_rays_down_onto_a_cell_hit_the_triangle_not_the_bilinear_patch(prec: Precision, offset: float) -> None:
    """A saddle cell (heights 0, 0.2 / 0.1, 0.7): straight down onto each half the height is that
    triangle's plane (both halves of the diagonal), not the bilinear interpolation; also 1e5 m away."""
    h00, h10, h01, h11 = 0.0, 0.2, 0.1, 0.7
    dx, dy = 0.75, 1.25                               # dyadic: the grid's points are exact at 1e5 m too
    base = np.array([offset, -offset / 4, 2.0])
    e = _engine(prec, elevation_grid_mesh((h00, h10, h01, h11), 2, dx, 2, dy), at=base)
    rng = np.random.default_rng(1)
    fx, fy = rng.uniform(0.01, 0.99, (2, 2000))
    o = base + np.c_[fx * dx, fy * dy, np.full(len(fx), 3.0)]
    fx, fy = (o[:, 0] - base[0]) / dx, (o[:, 1] - base[1]) / dy     # where the rays really are (1e5 m: rounded)
    lower = fy < fx                                   # below the diagonal (i, j)-(i+1, j+1)
    z = np.where(lower, h00 + (h10 - h00) * fx + (h11 - h10) * fy, h00 + (h11 - h01) * fx + (h01 - h00) * fy)
    bilinear = h00 * (1 - fx) * (1 - fy) + h10 * fx * (1 - fy) + h01 * (1 - fx) * fy + h11 * fx * fy
    assert np.abs(z - bilinear).max() > 0.05           # the two answers differ: the test can tell them apart
    d = np.broadcast_to([0.0, 0.0, -1.0], o.shape)
    hits = e.cast(o, np.ascontiguousarray(d))
    assert np.all(hits.shape == 0)
    assert np.abs(hits.distance - (3.0 - z)).max() <= BOUND[prec]
    assert lower.any() and (~lower).any()


@pytest.mark.parametrize("prec", BOTH)
def test_grazing_rays_along_a_ridge(prec: Precision) -> None:
    """A ridge along x (the middle row 1 m high, the others 0): rays sloping down in its vertical
    plane meet its crest, a line of shared edges, at the closed-form distance (no leak between the
    triangles either side); rays along it just below or above the crest pass."""
    nx, dx, dy = 6, 0.4, 0.5
    heights = [0.0] * nx + [1.0] * nx + [0.0] * nx
    e = _engine(prec, elevation_grid_mesh(tuple(heights), nx, dx, 3, dy))
    rng = np.random.default_rng(2)
    n = 500
    land = rng.uniform(0.05, (nx - 1) * dx - 0.05, n)         # where on the crest each ray lands
    slope = rng.uniform(1e-4, 0.05, n)                        # grazing: a twentieth to a ten-thousandth
    run = rng.uniform(0.1, 1.0, n)
    o = np.c_[land - run, np.full(n, dy), 1.0 + slope * run]
    d = np.c_[np.ones(n), np.zeros(n), -slope] / np.sqrt(1 + slope ** 2)[:, None]
    hits = e.cast(o, d)
    assert np.all(hits.shape == 0), "a ray leaked through the crest"
    if prec is Precision.EXACT:
        assert np.abs(hits.distance - run * np.sqrt(1 + slope ** 2)).max() <= 1e-12
    else:     # float32: the hit within 2e-6 m of the crest's height, so along a grazing ray that over its slope
        assert np.all(np.abs(hits.distance - run * np.sqrt(1 + slope ** 2)) <= 2e-6 * np.sqrt(1 + slope ** 2) / slope)
    if prec is Precision.EXACT:                               # float64 exactly: just above or below passes
        for dz in (1e-9, -1e-9):
            start = np.c_[np.full(n, -1.0), np.full(n, dy), np.full(n, 1.0 + dz)]
            along = np.ascontiguousarray(np.broadcast_to([1.0, 0.0, 0.0], start.shape))
            assert np.all(np.isinf(e.cast(start, along).distance))


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("offset", [0.0, 1e5])
def test_a_fan_of_rays_over_a_sloped_grid_sees_the_plane(prec: Precision, offset: float) -> None:
    """A planar grid z = a·x + b·y + c: a lidar-like fan of rays from above reads the plane's
    distance (EXACT 1e-12, FAST 2e-6), near the origin and 1e5 m away."""
    a, b, c = 0.15, -0.08, 0.3
    nx, ny, dx, dy = 21, 17, 0.5, 0.625               # dyadic: the grid's points are exact at 1e5 m too
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    heights = (a * i * dx + b * j * dy + c).reshape(-1)
    base = np.array([offset, offset / 2, 0.0])
    e = _engine(prec, elevation_grid_mesh(tuple(heights), nx, dx, ny, dy), at=base)
    origin = np.array([5.03, 4.77, 3.0])              # off the grid lines (FAST is not watertight along them)
    az, el = np.meshgrid(np.linspace(-math.pi, math.pi, 360, endpoint=False), np.linspace(-1.2, -0.5, 8))
    d = np.c_[(np.cos(el) * np.cos(az)).ravel(), (np.cos(el) * np.sin(az)).ravel(), np.sin(el).ravel()]
    o = np.broadcast_to(base + origin, d.shape)
    hits = e.cast(np.ascontiguousarray(o), d)
    t = (a * origin[0] + b * origin[1] + c - origin[2]) / (d[:, 2] - a * d[:, 0] - b * d[:, 1])
    p = origin + t[:, None] * d
    inside = (p[:, 0] > 1e-6) & (p[:, 0] < (nx - 1) * dx - 1e-6) & (p[:, 1] > 1e-6) & (p[:, 1] < (ny - 1) * dy - 1e-6)
    assert inside.sum() > 2000 and (~inside).sum() > 50
    assert np.abs(hits.distance[inside] - t[inside]).max() <= BOUND[prec]
    assert np.all(np.isinf(hits.distance[~inside] if prec is Precision.EXACT else hits.distance[~inside & (
        (p[:, 0] < -1e-3) | (p[:, 0] > (nx - 1) * dx + 1e-3) | (p[:, 1] < -1e-3) | (p[:, 1] > (ny - 1) * dy + 1e-3))]))


def _grid_world(heights: list[float], nx: int, ny: int, spacing: float, **extra) -> dict:
    corner = -(nx - 1) * spacing / 2.0
    return {"solids": [{"name": "terrain", "pose": {"translation": [corner, corner, 0.0]},
                        "geometry": {"type": "elevation_grid", "height": heights, "x_dimension": nx,
                                     "x_spacing": spacing, "y_dimension": ny, "y_spacing": spacing}, **extra}],
            "robots": [{"name": "r", "pose": {"translation": [0.0, 0.0, 1.0]},
                        "devices": [{"device": "Lidar", "name": "l", "horizontal_resolution": 90,
                                     "number_of_layers": 4, "vertical_field_of_view": 0.4, "tilt_angle": -0.9,
                                     "field_of_view": 1.5, "max_range": 20.0}]}]}


def test_a_lidar_over_a_yaml_elevation_grid_reads_the_plane() -> None:
    """A YAML world's sloped `elevation_grid` under a Simulation's lidar: every beam's range is the
    plane's distance, rounded to float32 as the range image is."""
    a, b, c = 0.1, 0.05, -0.2
    nx = ny = 17
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    heights = (a * (i * 0.5 - 4.0) + b * (j * 0.5 - 4.0) + c).reshape(-1).tolist()    # in world coordinates
    sim = Simulation(parse_world(_grid_world(heights, nx, ny, 0.5)), precision="exact")
    dev = sim.device("r/l")
    dev.enable(sim.basic_time_step)
    sim.step()
    pose = dev.world_pose(sim.robots["r"].pose)
    d = lmath.ray_directions(dev.params).reshape(-1, 3) @ pose.rotation.T
    o = pose.translation
    t = (a * o[0] + b * o[1] + c - o[2]) / (d[:, 2] - a * d[:, 0] - b * d[:, 1])
    image = dev.range_image.reshape(-1)
    assert np.all(np.isfinite(image))
    assert np.array_equal(image, t.astype(np.float32))


def test_yaml_bad_grids_are_one_line_naming_the_field(tmp_path: Path, capsys) -> None:
    good = {"type": "elevation_grid", "height": [0, 0, 0, 0], "x_dimension": 2, "y_dimension": 2}
    for bad, field, what in (({"height": [0, 0, 0]}, "geometry", "height has 3 values; x_dimension × y_dimension"),
                             ({"x_dimension": 1, "height": [0, 0]}, "geometry.x_dimension", "greater than or equal to 2"),
                             ({"y_spacing": -0.5}, "geometry.y_spacing", "greater than 0"),
                             ({"thickness": -1}, "geometry.thickness", "greater than or equal to 0")):
        p = tmp_path / "w.yaml"
        import yaml
        p.write_text(yaml.safe_dump({"solids": [{"name": "t", "geometry": {**good, **bad}}]}))
        assert cli(["validate", str(p)]) == 1
        err = capsys.readouterr()
        lines = [ln for ln in (err.out + err.err).splitlines() if "solids[0]" in ln]
        assert len(lines) == 1 and f"solids[0] (t).{field}:" in lines[0] and what in lines[0], lines


def test_the_grid_counts_against_the_triangle_limit() -> None:
    world = {"solids": [{"name": "t", "geometry": {"type": "elevation_grid", "height": [0.0] * 12,
                                                    "x_dimension": 4, "y_dimension": 3}}]}
    parse_world(world, limits=WorldLimits(triangles=12))                 # 2 · 3 · 2 = 12 triangles
    with pytest.raises(WorldError, match="the world's triangles: 12 exceeds the limit of 11"):
        parse_world(world, limits=WorldLimits(triangles=11))


def _wbt(tmp_path: Path, grid: str, name: str = "w.wbt") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + "WorldInfo { }\nDEF GROUND Solid {\n  name \"ground\"\n  children [\n    Shape {\n"
                 "      appearance PBRAppearance { baseColor 0.4 0.6 0.2 }\n"
                 f"      geometry DEF G ElevationGrid {{\n{grid}\n      }}\n    }}\n  ]\n"
                 "  boundingObject USE G\n}\n")
    return p


GRID = "        xDimension 3 xSpacing 0.5 yDimension 2 ySpacing 0.25\n        height [ 0 0.1 0.2 0.3 0.4 0.5 ]"


def test_a_wbt_terrain_loads_whole_seen_by_both_kinds_of_ray(tmp_path: Path, capsys) -> None:
    """A Solid whose Shape and boundingObject are one ElevationGrid: validate exits 0 with no loss,
    the grid is one shape seen by both kinds of ray, and `convert` writes it."""
    p = _wbt(tmp_path, GRID)
    w = load_world(p)
    assert not w.losses and not any("ElevationGrid" in x for x in w.warnings)
    (shape,) = w.world.solids[0].shapes
    assert shape.seen_by == "both"
    assert shape.geometry == wm.ElevationGrid(type="elevation_grid", height=(0, 0.1, 0.2, 0.3, 0.4, 0.5),
                                              x_dimension=3, x_spacing=0.5, y_dimension=2, y_spacing=0.25)
    assert cli(["validate", str(p)]) == 0
    assert capsys.readouterr().out.strip().endswith("w.wbt: OK")
    out = tmp_path / "w.yaml"
    assert cli(["convert", str(p), str(out)]) == 0
    assert "type: elevation_grid" in out.read_text()
    assert load_world(out).world.solids[0].shapes[0].geometry == shape.geometry
    sim = Simulation(w, precision="exact")
    for kind in (RayKind.BOUNDING, RayKind.VISUAL):     # down onto point (1, 1): 0.4 m high
        hit = sim.scene.engine.cast(np.array([[0.5, 0.25, 2.0]]), np.array([[0.0, 0.0, -1.0]]), kind=kind)
        assert abs(hit.distance[0] - 1.6) <= 1e-12


def test_wbt_grids_are_sanitised_as_webots_does_each_said_on_its_line(tmp_path: Path) -> None:
    """Webots' resets, each a warning naming file:line:col and the field: missing heights are 0,
    extra ones ignored, a non-positive spacing 1, a negative thickness 0; fewer than 2 points is no
    surface (nothing to see: not a loss)."""
    p = _wbt(tmp_path, "        xDimension 2 yDimension 2 xSpacing -1 thickness -2\n        height [ 1 2 3 ]")
    w = load_world(p)
    g = w.world.solids[0].shapes[0].geometry
    assert (g.height, g.x_spacing, g.thickness) == ((1, 2, 3, 0), 1.0, 0.0)
    said = [x for x in w.warnings if "ElevationGrid" in x]
    assert all(x.startswith(f"{p}:8:22: ") for x in said) and len(said) == 3, said
    assert any("ElevationGrid.height: 3 values for 2 x 2 = 4 points: the missing 1 are 0" in x for x in said)
    assert any("ElevationGrid.xSpacing: -1 is not positive: reset to 1" in x for x in said)
    p = _wbt(tmp_path, "        xDimension 2 yDimension 2\n        height [ 1 2 3 4 5 ]")
    assert any("ElevationGrid.height: 1 extra value(s) ignored" in x for x in load_world(p).warnings)
    p = _wbt(tmp_path, "        xDimension 1 yDimension 2\n        height [ 1 2 ]")
    w = load_world(p)
    assert not w.losses and w.world.solids[0].shapes == []
    assert any("fewer than 2 points along an axis is no surface" in x for x in w.warnings)


def test_wbt_bad_and_huge_grids_are_one_line_with_file_and_line(tmp_path: Path, capsys) -> None:
    """A 10^6 x 10^6 grid is refused before anything is made (one line naming the field); a height
    that is not a number names its line too."""
    p = _wbt(tmp_path, "        xDimension 1000000\n        yDimension 1000000\n        height [ 0 0 0 0 ]")
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value) == (f"{p}: line 9, column 9: ElevationGrid.xDimension: 1,000,000 x 1,000,000 = "
                              "1,000,000,000,000 points: more than 4,000,000 points in one grid are refused "
                              "(raise the limits with --allow-large)")
    assert cli(["validate", str(p)]) == 1
    err = [ln for ln in capsys.readouterr().err.splitlines() if "ElevationGrid" in ln]
    assert len(err) == 1 and "ElevationGrid.xDimension" in err[0] and "line 9" in err[0]
    p = _wbt(tmp_path, "        xDimension 1500 yDimension 1500\n        height [ 0 ]")   # padded with 0s: 2.25M
    with pytest.raises(WorldError, match=r"line 9, column 9: ElevationGrid.xDimension: the world's ElevationGrids have "
                                         r"more than 4,000,000 points together \(each use of a DEF counts"):
        load_world(p)                                                # used twice (shape and boundingObject)
    p = _wbt(tmp_path, '        xDimension 2 yDimension 2\n        height [ 0 "a" 0 0 ]')
    with pytest.raises(WorldError, match=r"line 10, column 9: ElevationGrid.height: expected numbers"):
        load_world(p)


def test_scaled_wbt_grids_are_the_affine_image(tmp_path: Path) -> None:
    """Under a Transform's scale a visual grid is scaled exactly (spacings by x and y, heights by z);
    a mirrored one becomes its triangles, mapped."""
    for scale, kind in (("2 3 0.5", "elevation_grid"), ("-1 1 1", "triangles")):
        p = tmp_path / "s.wbt"
        p.write_text(HEADER + "Solid { children [ Transform { scale " + scale + " children [ Shape { geometry "
                     "ElevationGrid { xDimension 2 yDimension 2 height [ 0 1 2 3 ] } } ] } ] }\n")
        g = load_world(p).world.solids[0].shapes[0].geometry
        assert g.type == kind
        if kind == "elevation_grid":
            assert (g.x_spacing, g.y_spacing, g.height) == (2.0, 3.0, (0.0, 0.5, 1.0, 1.5))
        else:
            assert [list(v) for v in g.vertices] == [[0, 0, 0], [-1, 0, 1], [0, 1, 2], [-1, 1, 3]]
            v = np.asarray(g.vertices)[np.asarray(g.faces)]
            assert np.all(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])[:, 2] > 0)   # still wound up


def test_texture_coordinates_are_webots_picking() -> None:
    """u = x/W, v = 1 − y/D over the grid's extent (WbElevationGrid::pickUVCoordinate)."""
    uv = tc.elevation_grid_uv(np.array([[0.0, 0.0, 5.0], [1.0, 0.5, -1.0], [2.0, 2.0, 0.0]]), (2.0, 2.0))
    assert uv.tolist() == [[0.0, 1.0], [0.5, 0.75], [1.0, 0.0]]


def test_an_infra_red_sensor_reads_the_texel_under_it(tmp_path: Path) -> None:
    """A textured grid: the left half of the image black, the right half white; infra-red sensors
    looking down over each half read the reflectance of the texel under them."""
    from PIL import Image

    img = np.zeros((4, 4, 3), dtype=np.uint8)
    img[:, 2:] = 255
    Image.fromarray(img).save(tmp_path / "half.png")
    world = {"solids": [{"name": "terrain", "geometry": {"type": "elevation_grid", "height": [0.0] * 9,
                                                        "x_dimension": 3, "x_spacing": 1.0, "y_dimension": 3,
                                                        "y_spacing": 1.0},
                         "appearance": {"base_color": [1, 1, 1], "texture": "half.png"}}],
             "robots": [{"name": "r", "pose": {"translation": [0.0, 0.0, 0.5]},
                         "devices": [{"device": "DistanceSensor", "name": name, "type": "infra-red",
                                      "pose": {"translation": [x, 1.0, 0.0], "rotation": [0, 1, 0, math.pi / 2]},
                                      "lookup_table": [[0, 0, 0], [10, 10, 0]]}
                                     for name, x in (("dark", 0.5), ("light", 1.5))]}]}
    sim = Simulation(parse_world(world, base_dir=tmp_path), precision="exact")
    for dev in sim.all_devices():
        dev.enable(sim.basic_time_step)
    sim.step()
    assert sim.device("r/light").value == pytest.approx(0.5, abs=1e-9)            # white: d / 1
    assert sim.device("r/dark").value == pytest.approx(0.5 / 0.2, abs=1e-9)       # black: d / 0.2


def test_a_terrain_never_stops_a_robot() -> None:
    """Kinematic contact: a terrain is ground (as a floor plane), whatever its relief."""
    mesh = elevation_grid_mesh((0.0, 2.0, 0.0, 2.0), 2, 1.0, 2, 1.0)
    assert contact.obstacle("t", -1, mesh, Pose.identity()) is None


def _brute_force(v: np.ndarray, f: np.ndarray, o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Nearest float64 Möller–Trumbore hit of every ray on every triangle (the reference)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    e1, e2 = b - a, c - a
    best = np.full(len(o), np.inf)
    for k in range(len(o)):
        p = np.cross(d[k], e2)
        det = (e1 * p).sum(1)
        inv = 1.0 / det
        s = o[k] - a
        u = (s * p).sum(1) * inv
        q = np.cross(s, e1)
        w = (d[k] * q).sum(1) * inv
        t = (e2 * q).sum(1) * inv
        ok = (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 0)
        if ok.any():
            best[k] = t[ok].min()
    return best


@pytest.mark.parametrize("prec", BOTH)
def test_a_rough_terrain_against_brute_force(prec: Precision) -> None:
    """Random heights on a 16 x 12 grid, rays from above in every direction (many crossing cells
    near their diagonals and edges): the nearest hit of every ray is the brute-force float64 answer
    over all 330 triangles (EXACT 1e-12; FAST's point within 2e-6 m of the surface, off grazing
    rays) — no leak, no wrong triangle."""
    rng = np.random.default_rng(7)
    nx, ny, dx, dy = 16, 12, 0.25, 0.375
    heights = rng.uniform(-0.3, 0.3, nx * ny)
    v, f = elevation_grid(heights, nx, dx, ny, dy)
    e = _engine(prec, elevation_grid_mesh(tuple(heights), nx, dx, ny, dy))
    n = 1500
    o = np.c_[rng.uniform(-0.5, 4.2, n), rng.uniform(-0.5, 4.6, n), rng.uniform(0.5, 1.5, n)]
    target = np.c_[rng.uniform(0, (nx - 1) * dx, n), rng.uniform(0, (ny - 1) * dy, n), np.zeros(n)]
    d = target - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    ref = _brute_force(v, f, o, d)
    hits = e.cast(o, d)
    both = np.isfinite(ref) & np.isfinite(hits.distance)
    steep = np.abs(d[:, 2]) > 0.3
    if prec is Precision.EXACT:
        assert np.array_equal(np.isfinite(ref), np.isfinite(hits.distance))
        assert np.abs(hits.distance[both] - ref[both]).max() <= 1e-12
    else:
        assert np.array_equal(np.isfinite(ref)[steep], np.isfinite(hits.distance)[steep])
        k = both & steep      # float32: the hit point within 2e-6 m of the surface (along its normal)
        cos_in = np.abs((hits.normal[k] * d[k]).sum(1))
        assert (np.abs(hits.distance[k] - ref[k]) * cos_in).max() <= 2e-6
    assert np.count_nonzero(np.isfinite(ref)) > 1000
