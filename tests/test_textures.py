"""Textures that infra-red sensors read (issue 21): Webots' texture coordinates of every geometry at
known points, TextureTransform and repeat, nearest texel, colour combination, limits, laziness; and
closed-form readings through the whole pipeline (FAST and EXACT): over a texel of red R an
infra-red sensor at distance d reads the lookup of d / (0.2 + 0.8·R/255)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import texcoords as tc
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.textures import TextureImage, TriangleLocator, load_alpha, load_image, transform_uv

DOWN = [0.0, 1.0, 0.0, math.pi / 2]      # a device's +x axis turned to world -z
H = 0.0625                               # sensor height above the floor (exact in binary)
LUT = [[0.0, 0.0, 0.0], [10.0, 10000.0, 0.0]]     # value = 1000/m up to 10 m


def png(path: Path, pixels) -> Path:
    """An RGB image from rows of (r, g, b) (top row first)."""
    Image.fromarray(np.asarray(pixels, dtype=np.uint8)).save(path)
    return path


def expected(d: float, red: float, roughness: float = 0.0, occlusion: float = 0.0) -> float:
    return 1000.0 * d / (0.2 + 0.8 * red * (1 - 0.5 * roughness) * (1 - 0.5 * occlusion))


def ir(name: str, x: float, y: float, z: float = H, rotation=DOWN) -> dict:
    return {"device": "DistanceSensor", "name": name, "type": "infra-red", "lookup_table": LUT,
            "pose": {"translation": [x, y, z], "rotation": rotation}}


def sim_of(tmp_path: Path, solids: list[dict], devices: list[dict], precision: str = "exact") -> Simulation:
    data = {"solids": solids, "robots": [{"name": "r", "devices": devices}]}
    return Simulation(parse_world(data, base_dir=tmp_path), precision=precision)


def read_all(sim: Simulation) -> dict[str, float]:
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    return {d.config.name: d.value for d in sim.all_devices() if hasattr(d, "value")}


# 4 x 4 texels with distinct reds (row 0 is the image's top row)
REDS = np.array([[0, 17, 34, 51], [68, 85, 102, 113], [136, 153, 170, 187], [204, 221, 238, 255]])


def board(tmp_path: Path) -> Path:
    return png(tmp_path / "board.png", np.stack([REDS, 255 - REDS, np.full_like(REDS, 7)], axis=-1))


# ------------------------------------------------------------------ closed-form readings

@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_each_texel_of_a_plane_read_through_the_pipeline(tmp_path: Path, precision: str) -> None:
    """A 1 m x 1 m plane with a 4x4 image: u = x + 0.5, v = -y + 0.5 (WbPlane), so the texel under
    (x, y) is row floor((0.5 - y)·4), column floor((x + 0.5)·4)."""
    board(tmp_path)
    floor = {"name": "floor", "geometry": {"type": "plane", "size": [1.0, 1.0]},
             "appearance": {"texture": "board.png"}}
    centres = [(-0.375 + 0.25 * c, 0.375 - 0.25 * r, r, c) for r in range(4) for c in range(4)]
    sim = sim_of(tmp_path, [floor], [ir(f"s{r}{c}", x, y) for x, y, r, c in centres], precision)
    values = read_all(sim)
    for _, _, r, c in centres:
        assert values[f"s{r}{c}"] == pytest.approx(expected(H, REDS[r, c] / 255), rel=1e-12), (r, c)
    assert sim.counters["texture_lookups"] == 16


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_colour_combination_base_colour_transparency_and_maps(tmp_path: Path, precision: str) -> None:
    """red = base_color.r·(1 − transparency)·texel.r; roughness and occlusion from their maps' red."""
    png(tmp_path / "tex.png", [[(102, 0, 0)]])
    png(tmp_path / "rough.png", [[(128, 9, 9)]])
    png(tmp_path / "occl.png", [[(51, 200, 200)]])
    solids = [
        {"name": "a", "pose": {"translation": [0, 0, 0]}, "geometry": {"type": "plane", "size": [0.1, 0.1]},
         "appearance": {"base_color": [0.5, 1, 1], "transparency": 0.25, "roughness": 0.3, "texture": "tex.png"}},
        {"name": "b", "pose": {"translation": [1, 0, 0]}, "geometry": {"type": "plane", "size": [0.1, 0.1]},
         "appearance": {"roughness": 0.3, "texture": "tex.png", "roughness_map": "rough.png", "occlusion_map": "occl.png"}},
        {"name": "c", "pose": {"translation": [2, 0, 0]}, "geometry": {"type": "plane", "size": [0.1, 0.1]},
         "appearance": {"roughness": 0.3, "roughness_map": "rough.png"}},      # maps without a texture: not read
    ]
    v = read_all(sim_of(tmp_path, solids, [ir("a", 0, 0), ir("b", 1, 0), ir("c", 2, 0)], precision))
    assert v["a"] == pytest.approx(expected(H, 0.5 * 0.75 * 102 / 255, 0.3), rel=1e-12)
    assert v["b"] == pytest.approx(expected(H, 102 / 255, 128 / 255, 51 / 255), rel=1e-12)
    assert v["c"] == pytest.approx(expected(H, 1.0, 0.3), rel=1e-12)


def _webots_ir_test_world(tmp_path: Path) -> Path:
    """The situation of Webots' tests/api distance_sensor_infra-red world, in our own file: a NUE
    world, two boards 0.065 m under two infra-red sensors, one an Appearance whose material
    (diffuse 0.75 1 1) is textured with a greenish image (red 113), one an untextured PBRAppearance."""
    (tmp_path / "textures").mkdir()
    png(tmp_path / "textures" / "greenish.png", np.full((8, 8, 3), (113, 200, 40)))
    board_pose = 'rotation 1 0 0 -1.5707963267948966'
    (tmp_path / "ir.wbt").write_text(f"""#VRML_SIM R2023b utf8
WorldInfo {{ coordinateSystem "NUE" }}
Solid {{
  translation 0 0.005 0
  children [
    Pose {{ translation 0 0 -0.075 {board_pose} children [ Shape {{
      appearance Appearance {{ material Material {{ diffuseColor 0.75 1 1 }}
                              texture ImageTexture {{ url [ "textures/greenish.png" ] }} }}
      geometry Plane {{ size 0.15 0.15 }} }} ] }}
    Pose {{ translation 0 0 0.075 {board_pose} children [ Shape {{
      appearance PBRAppearance {{ baseColor 0.729412 0.741176 0.713725 roughness 0.5 metalness 0 }}
      geometry Plane {{ size 0.15 0.15 }} }} ] }}
  ]
}}
Robot {{
  translation 0 0.09 0
  children [
    DistanceSensor {{ translation 0 -0.02 0.08 rotation 0 0 1 -1.5708 name "ds0"
                     lookupTable [ 0 0 0, 0.2 2000 0 ] type "infra-red" }}
    DistanceSensor {{ translation 0 -0.02 -0.08 rotation 0 0 1 -1.5708 name "ds1"
                     lookupTable [ 0 0 0, 0.2 2000 0 ] type "infra-red" }}
  ]
  controller "<extern>"
}}
""")
    return tmp_path / "ir.wbt"


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_webots_infra_red_test_situation(tmp_path: Path, precision: str) -> None:
    """Webots reads 1172.206506 over the textured board and 1019.3725 over the PBR one (its test's
    expectations); both follow from the formula: the texture replaces the diffuse colour, so red =
    113/255, and the PBR board reads baseColor 0.729412 with roughness 0.5, at d = 0.065 m, 10000/m."""
    sim = Simulation.from_file(_webots_ir_test_world(tmp_path), precision=precision)
    assert not [w for w in sim.loaded.warnings if "texture" in w]
    v = read_all(sim)
    d = 0.065
    assert 10 * expected(d, 113 / 255) == pytest.approx(1172.2065063649, rel=1e-12)
    assert v["ds1"] == pytest.approx(10 * expected(d, 113 / 255), rel=1e-9)
    assert v["ds1"] == pytest.approx(1172.206506, abs=1e-3)      # Webots' own expectation
    assert v["ds0"] == pytest.approx(10 * expected(d, 0.729412, 0.5), rel=1e-9)
    assert v["ds0"] == pytest.approx(1019.3725, abs=1e-3)


def test_a_texture_webots_could_not_load_reads_the_untextured_colour(tmp_path: Path, monkeypatch) -> None:
    """Missing file (or a webots:// url without a Webots installation): a warning, and Webots'
    reading of a texture it could not load: an Appearance's material diffuseColor (not white)."""
    monkeypatch.delenv("WEBOTS_HOME", raising=False)
    path = _webots_ir_test_world(tmp_path)
    (tmp_path / "textures" / "greenish.png").unlink()
    sim = Simulation.from_file(path)
    notes = [w for w in sim.loaded.warnings if "texture" in w]
    assert len(notes) == 1 and "1 texture not loaded" in notes[0] and "greenish.png" in notes[0]
    assert read_all(sim)["ds1"] == pytest.approx(10 * expected(0.065, 0.75), rel=1e-9)
    path.write_text(path.read_text().replace("textures/greenish.png", "webots://projects/x.png"))
    notes = [w for w in load_world(path).warnings if "texture" in w]
    assert len(notes) == 1 and '"webots://projects/x.png" not found' in notes[0] and "--webots-home" in notes[0]


def test_proto_relative_and_webots_texture_urls_are_read_where_they_are(tmp_path: Path, monkeypatch) -> None:
    """A PROTO's ImageTexture url is relative to the PROTO file, a webots:// url names the Webots
    installation's file (as mesh urls): both read in place, and infra-red sensors read their texels."""
    from _protos import proto_file, webots_home, world_file

    home = webots_home(tmp_path / "webots", monkeypatch)
    (home / "projects" / "textures").mkdir(parents=True)
    Image.new("RGB", (4, 4), (51, 0, 0)).save(home / "projects" / "textures" / "dark.png")
    protos = tmp_path / "project" / "protos"
    (protos / "textures").mkdir(parents=True)
    Image.new("RGB", (4, 4), (153, 0, 0)).save(protos / "textures" / "mid.png")
    proto_file(protos, "Tiles", """[ field SFVec3f translation 0 0 0 field SFString name "tiles" ]
{ Solid { translation IS translation name IS name children [
    Shape { appearance Appearance { texture ImageTexture { url [ "textures/mid.png" ] } } geometry Plane { size 0.2 0.2 } }
    Pose { translation 0.5 0 0 children [ Shape { appearance PBRAppearance {
      baseColorMap ImageTexture { url [ "webots://projects/textures/dark.png" ] } } geometry Plane { size 0.2 0.2 } } ] } ] } }""")
    w = world_file(tmp_path / "project" / "worlds", """Tiles { }
Robot { name "r" children [
  DistanceSensor { translation 0 0 0.01 rotation 0 1 0 1.5707963267948966 name "a" type "infra-red" lookupTable [ 0 0 0, 1 1000 0 ] }
  DistanceSensor { translation 0.5 0 0.01 rotation 0 1 0 1.5707963267948966 name "b" type "infra-red" lookupTable [ 0 0 0, 1 1000 0 ] } ] }
""", ["../protos/Tiles.proto"])
    loaded = load_world(w)
    assert not [m for m in loaded.warnings if "texture" in m]
    urls = [p.appearance.texture.url for p in loaded.world.solids[0].shapes]
    assert urls == [str((protos / "textures" / "mid.png").resolve()), str((home / "projects/textures/dark.png").resolve())]
    sim = Simulation(loaded)
    v = read_all(sim)
    assert v["a"] == pytest.approx(expected(0.01, 153 / 255), rel=1e-9)
    assert v["b"] == pytest.approx(expected(0.01, 51 / 255), rel=1e-9)
    # a world file naming a file outside its folder is still refused
    bad = world_file(tmp_path / "project" / "worlds", f"""Solid {{ children [ Shape {{
  appearance Appearance {{ texture ImageTexture {{ url [ "{home}/projects/textures/dark.png" ] }} }}
  geometry Plane {{ }} }} ] }}
""", name="bad.wbt")
    with pytest.raises(WorldError, match="leaves the world's folder"):
        load_world(bad)


# ------------------------------------------------------------------ texture coordinates at known points

def test_box_faces_centres_edges_corners() -> None:
    s = (2.0, 4.0, 8.0)
    hx, hy, hz = 1.0, 2.0, 4.0
    centres = [(hx, 0, 0), (-hx, 0, 0), (0, 0, -hz), (0, 0, hz), (0, hy, 0), (0, -hy, 0)]
    assert np.array_equal(tc.box_uv(np.array(centres, dtype=float), s), np.full((6, 2), 0.5))
    # a quarter of the way along each face's axes: the orientation of each face (WbBox)
    pts = np.array([(hx, 1.0, 2.0), (-hx, 1.0, 2.0), (0.5, 1.0, -hz), (0.5, 1.0, hz), (0.5, hy, 2.0), (0.5, -hy, 2.0)])
    want = [(0.75, 0.25), (0.25, 0.25), (0.75, 0.75), (0.75, 0.25), (0.25, 0.25), (0.75, 0.25)]
    assert np.allclose(tc.box_uv(pts, s), want, atol=1e-15)
    # an edge or corner belongs to the first face in Webots' order: front, back, bottom, top, left, right
    assert tc.box_uv(np.array([(hx, hy, hz)]), s).tolist() == [[1.0, 0.0]]          # front
    assert tc.box_uv(np.array([(0.0, hy, hz)]), s).tolist() == [[0.5, 0.0]]         # top before left
    assert tc.box_uv(np.array([(0.0, -hy, -hz)]), s).tolist() == [[0.5, 0.0]]       # bottom before right
    # a FAST-like point slightly off the face still takes that face
    assert np.allclose(tc.box_uv(np.array([(hx + 3e-8, 1.0, 2.0)]), s), [(0.75, 0.25)], atol=1e-7)


def test_box_matches_webots_rendering_coordinates_inside_each_face() -> None:
    """Webots' unit box mesh (wren StaticMesh::createUnitBox) gives each face vertex a texture
    coordinate; just inside each corner the picked (u, v) is that vertex's (set 0 = the whole image)."""
    faces = {  # face: [(vertex, uv)] in the renderer's order
        "left": [((-.5, .5, .5), (1, 0)), ((.5, .5, .5), (0, 0)), ((.5, .5, -.5), (0, 1)), ((-.5, .5, -.5), (1, 1))],
        "back": [((-.5, .5, .5), (0, 0)), ((-.5, .5, -.5), (0, 1)), ((-.5, -.5, -.5), (1, 1)), ((-.5, -.5, .5), (1, 0))],
        "bottom": [((.5, -.5, -.5), (1, 0)), ((-.5, -.5, -.5), (0, 0)), ((-.5, .5, -.5), (0, 1)), ((.5, .5, -.5), (1, 1))],
        "right": [((.5, -.5, .5), (1, 0)), ((-.5, -.5, .5), (0, 0)), ((-.5, -.5, -.5), (0, 1)), ((.5, -.5, -.5), (1, 1))],
        "front": [((.5, .5, -.5), (1, 1)), ((.5, .5, .5), (1, 0)), ((.5, -.5, .5), (0, 0)), ((.5, -.5, -.5), (0, 1))],
        "top": [((.5, -.5, .5), (1, 1)), ((.5, .5, .5), (1, 0)), ((-.5, .5, .5), (0, 0)), ((-.5, -.5, .5), (0, 1))],
    }
    normal = {"left": (0, 1, 0), "back": (-1, 0, 0), "bottom": (0, 0, -1), "right": (0, -1, 0), "front": (1, 0, 0),
              "top": (0, 0, 1)}
    for face, corners in faces.items():
        n = np.array(normal[face], dtype=float)
        for vertex, uv in corners:
            p = np.array(vertex) * 0.98 + n * 0.5 * 0.02          # pulled toward the face centre, on the face
            assert np.allclose(tc.box_uv(p[None], (1, 1, 1))[0], uv, atol=0.011), (face, vertex)


def test_sphere_poles_equator_and_seam() -> None:
    r = 2.0
    pts = np.array([(0, 0, r), (0, 0, -r), (0, -r, 0), (r, 0, 0), (-r, 0, 0), (0, r, 0), (-0.0, r, 0)])
    uv = tc.sphere_uv(pts, r)
    assert uv[:, 1].tolist() == [0.0, 1.0, 0.5, 0.5, 0.5, 0.5, 0.5]
    assert uv[2:, 0].tolist() == [0.5, 0.75, 0.25, 1.0, 0.0]        # the seam is on +y: 1 on x >= +0, 0 on x = -0
    lat = math.radians(30)
    p = np.array([[r * math.cos(lat), 0, r * math.sin(lat)]])
    assert np.allclose(tc.sphere_uv(p, r), [[0.75, 0.5 - 1 / 6]], atol=1e-15)
    # FAST-like points on a shell outside the sphere map as their projection onto it
    assert np.allclose(tc.sphere_uv(p * 1.003, r), tc.sphere_uv(p, r), atol=1e-12)


def test_cylinder_side_caps_rim_and_seam() -> None:
    r, h = 0.5, 2.0
    side = np.array([(0, r, 0.5), (r, 0, 0.5), (-r, 0, -0.5), (0, -r, 0), (0, r, 1.0), (0, r, -1.0)])
    uv = tc.cylinder_uv(side, r, h)
    assert uv[:, 0].tolist() == [0.0, 0.75, 0.25, 0.5, 0.0, 0.0]
    assert uv[:, 1].tolist() == [0.25, 0.25, 0.75, 0.5, 0.0, 1.0]      # the rims belong to the side
    caps = np.array([(0, 0, 1.0), (0.25, 0, 1.0), (0, 0.25, 1.0), (0, 0.25, -1.0), (-0.25, -0.25, -1.0)])
    assert tc.cylinder_uv(caps, r, h).tolist() == [[0.5, 0.5], [0.75, 0.5], [0.5, 0.25], [0.5, 0.75], [0.25, 0.25]]
    # Webots' rendering of the side (wren createUnitCylinder): x = sin a, y = cos a, u = 1 - a/(2 pi)
    a = np.linspace(0.1, 6.1, 13)
    ring = np.stack([r * np.sin(a), r * np.cos(a), np.zeros_like(a)], axis=1)
    assert np.allclose(tc.cylinder_uv(ring, r, h)[:, 0], 1 - a / (2 * math.pi), atol=1e-12)


def test_capsule_body_bands_and_poles() -> None:
    r, h, sub = 1.0, 2.0, 12                          # sub/4 = 3 latitude bands per hemisphere
    body = np.array([(r, 0, 0), (0, -r, 1.0), (0, -r, -1.0)])
    uv = tc.capsule_uv(body, r, h, sub)
    assert np.allclose(uv[:, 1], [0.5, 1 / 3, 2 / 3], atol=1e-15)
    assert np.allclose(uv[:, 0], [0.75, 0.5, 0.5], atol=1e-15)
    # a band boundary on the bottom hemisphere: z_i = r sin(pi/6) starts band 2: v = (1 + 6) / 9
    zi = r * math.sin(math.pi / 6)
    p = np.array([(math.sqrt(r * r - zi * zi), 0, -1.0 - zi)])
    assert tc.capsule_uv(p, r, h, sub)[0, 1] == pytest.approx(7 / 9, abs=1e-15)
    assert tc.capsule_uv(p * [1, 1, -1], r, h, sub)[0, 1] == pytest.approx(2 / 9, abs=1e-15)  # top: 1 - v
    # Webots' quirk at the exact poles: v = 0 at the bottom pole, 1 at the top one
    assert tc.capsule_uv(np.array([(0, 0, -2.0), (0, 0, 2.0)]), r, h, sub)[:, 1].tolist() == [0.0, 1.0]


def test_plane_corners_and_infinite_plane() -> None:
    pts = np.array([(0, 0, 0), (1.0, 0.5, 0), (-1.0, -0.5, 0), (0.5, 0, 0)])
    assert tc.plane_uv(pts, (2.0, 1.0)).tolist() == [[0.5, 0.5], [1.0, 0.0], [0.0, 1.0], [0.75, 0.5]]
    assert tc.plane_uv(pts, None).tolist() == [[0.5, 0.5]] * 4


def test_triangle_interpolation_and_default_mapping() -> None:
    corners = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])
    assert tc.triangle_uv(corners, np.array([0.25]), np.array([0.5])).tolist() == [[0.25, 0.5]]
    # the default mapping (no texCoord): u along the longest side (x, 4 m), v = 1 - y / 4
    v = np.array([(0, 0, 0), (4, 0, 0), (4, 2, 0), (0, 2, 1)])
    uv = tc.default_triangle_uv(v, np.array([[0, 1, 2], [0, 2, 3]]))
    assert uv.tolist() == [[[0, 1], [1, 1], [1, 0.5]], [[0, 1], [1, 0.5], [0, 0.5]]]


# ------------------------------------------------------------------ TextureTransform, repeat, nearest texel

def _wren_matrix(t: wm.TextureTransform) -> np.ndarray:
    """wren TextureTransform::updateMatrix as 4x4 matrices (glm's column-major constructors
    transcribed as rows): −C·S·R·C·T."""
    (cx, cy), (sx, sy), (px, py), a = t.center, t.scale, t.translation, t.rotation
    def tr(x, y):
        m = np.eye(4)
        m[0, 3], m[1, 3] = x, y
        return m
    s = np.diag([sx, sy, 1.0, 1.0])
    r = np.eye(4)
    r[:2, :2] = [[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]]
    return tr(-cx, cy + 1) @ s @ r @ tr(cx, -cy - 1) @ tr(px, -py)


@pytest.mark.parametrize("fields", [dict(scale=(2, 3)), dict(rotation=0.7), dict(translation=(0.1, 0.2)),
                                    dict(center=(0.3, 0.4), rotation=-1.1, scale=(0.5, 1.5), translation=(0.25, -0.5))])
def test_texture_transform_is_webots_matrix(fields: dict) -> None:
    t = wm.TextureTransform(**fields)
    uv = np.random.default_rng(3).uniform(-1, 2, (50, 2))
    want = (np.c_[uv, np.zeros(50), np.ones(50)] @ _wren_matrix(t).T)[:, :2]
    assert np.allclose(transform_uv(uv, t), want, atol=1e-12)
    assert transform_uv(uv, None) is uv


def test_scale_tiles_from_the_image_bottom() -> None:
    """X3D: a scale keeps (s, t) = (0, 0), the image's bottom-left corner, in place."""
    t = wm.TextureTransform(scale=(2, 2))
    assert transform_uv(np.array([[0.0, 1.0], [0.5, 0.5], [0.25, 0.75]]), t).tolist() == [[0, 1], [1, 0], [0.5, 0.5]]


def test_wrap_repeat_and_clamp_nearest_texel() -> None:
    img = np.zeros((2, 4, 3), dtype=np.uint8)
    img[..., 0] = [[0, 1, 2, 3], [4, 5, 6, 7]]
    uv = np.array([[0.1, 0.1], [1.3, 0.6], [-0.2, -0.3], [1.0, 1.0], [0.0, 0.0], [-1e-20, 0.5]])
    rep = TextureImage(img, True, True).texels(uv, 0) * 255
    assert rep.tolist() == [0, 5, 7, 0, 0, 7]          # fmod: 1.3 -> 0.3, -0.2 -> 0.8, 1.0 -> 0; -1e-20 + 1 -> 1.0 -> last
    clamp = TextureImage(img, False, False).texels(uv, 0) * 255
    assert clamp.tolist() == [0, 7, 0, 7, 0, 4]         # clamped to [0, 1], the last texel at 1.0
    mixed = TextureImage(img, True, False).texels(uv, 0) * 255
    assert mixed.tolist() == [0, 5, 3, 4, 0, 7]


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_texture_transform_and_repeat_through_the_pipeline(tmp_path: Path, precision: str) -> None:
    """The board tiled 2x2 by a scale (repeat on), and clamped (repeat off) on a second plane."""
    board(tmp_path)
    app = {"texture": {"url": "board.png"}, "texture_transform": {"scale": [2, 2]}}
    solids = [{"name": "a", "geometry": {"type": "plane", "size": [1, 1]}, "appearance": app},
              {"name": "b", "pose": {"translation": [2, 0, 0]}, "geometry": {"type": "plane", "size": [1, 1]},
               "appearance": {**app, "texture": {"url": "board.png", "repeat_s": False, "repeat_t": False}}}]
    # (x, y) = (0.3125, 0.3125): u = 0.8125, v = 0.1875 -> (1.625, -0.625) -> repeat (0.625, 0.375): row 1, col 2
    #                                                  -> clamp (1, 0): row 0, col 3
    v = read_all(sim_of(tmp_path, solids, [ir("a", 0.3125, 0.3125), ir("b", 2.3125, 0.3125)], precision))
    assert v["a"] == pytest.approx(expected(H, REDS[1, 2] / 255), rel=1e-12)
    assert v["b"] == pytest.approx(expected(H, REDS[0, 3] / 255), rel=1e-12)


# ------------------------------------------------------------------ every geometry through the pipeline

def _aim(name: str, target, direction) -> dict:
    """A sensor 0.5 m back from ``target`` along ``direction`` (unit), looking at it."""
    d = np.asarray(direction, dtype=float)
    o = np.asarray(target, dtype=float) - 0.5 * d
    axis = np.cross([1.0, 0, 0], d)
    ang = math.acos(max(-1.0, min(1.0, d[0])))
    rot = [0, 0, 1, 0] if np.linalg.norm(axis) < 1e-12 else [*(axis / np.linalg.norm(axis)), ang]
    if np.linalg.norm(axis) < 1e-12 and d[0] < 0:
        rot = [0, 0, 1, math.pi]
    return ir(name, *o, rotation=rot)


def _sph(lon: float, lat: float) -> tuple[float, float, float]:
    """Unit vector with atan2(x, -y) = lon and asin(z) = lat."""
    return (math.cos(lat) * math.sin(lon), -math.cos(lat) * math.cos(lon), math.sin(lat))


GEOMETRY_CASES = [
    # (geometry, hit point on it, ray direction, expected (u, v))
    ({"type": "box", "size": [0.4, 0.4, 0.4]}, (0.2, 0.05, 0.05), (-1, 0, 0), (0.625, 0.375)),
    ({"type": "box", "size": [0.4, 0.4, 0.4]}, (0.05, -0.05, 0.2), (0, 0, -1), (0.625, 0.625)),
    # sphere: longitude 0.4 from -y, latitude 0.3: u = 0.5 + 0.4/(2 pi), v = 0.5 - 0.3/pi
    ({"type": "sphere", "radius": 0.2}, 0.2 * np.array(_sph(0.4, 0.3)), -np.array(_sph(0.4, 0.3)),
     (0.5 + 0.4 / (2 * math.pi), 0.5 - 0.3 / math.pi)),
    # cylinder side at theta = 0.4 (x = -r sin, y = r cos), z = 0.05: u = 0.4/(2 pi), v = 1 - 0.25/0.4
    ({"type": "cylinder", "radius": 0.2, "height": 0.4}, (-0.2 * math.sin(0.4), 0.2 * math.cos(0.4), 0.05),
     (math.sin(0.4), -math.cos(0.4), 0), (0.4 / (2 * math.pi), 0.375)),
    ({"type": "cylinder", "radius": 0.2, "height": 0.4}, (0.05, -0.05, 0.2), (0, 0, -1), (0.625, 0.625)),
    # capsule body where atan2(x, -y) = -2: u = (pi - 2)/(2 pi), v = (2 - 0.2/0.3)/3
    ({"type": "capsule", "radius": 0.1, "height": 0.3}, (0.1 * math.sin(-2), -0.1 * math.cos(-2), 0.05),
     (-math.sin(-2), math.cos(-2), 0), ((math.pi - 2) / (2 * math.pi), 4 / 9)),
]


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("case", range(len(GEOMETRY_CASES)))
def test_primitive_texels_through_the_pipeline(tmp_path: Path, precision: str, case: int) -> None:
    geometry, point, direction, (u, v) = GEOMETRY_CASES[case]
    board(tmp_path)
    solid = {"name": "thing", "pose": {"translation": [0.0, 0.0, 1.0]}, "geometry": geometry,
             "appearance": {"texture": "board.png"}}
    target = np.asarray(point) + [0, 0, 1.0]
    # a twin with red_color_sensitivity 0 reads the distance itself (FAST sees curved shells)
    sim = sim_of(tmp_path, [solid], [_aim("s", target, direction),
                                     {**_aim("d", target, direction), "red_color_sensitivity": 0.0}], precision)
    values = read_all(sim)
    d = values["d"] / 1000.0
    assert d == pytest.approx(0.5, abs=1e-12 if precision == "exact" else 2e-3)
    row, col = min(int(v * 4), 3), min(int(u * 4), 3)
    assert values["s"] == pytest.approx(expected(d, REDS[row, col] / 255), rel=1e-12)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_indexed_face_set_tex_coords_and_mesh_file_uvs(tmp_path: Path, precision: str) -> None:
    board(tmp_path)
    quad = {"type": "triangles", "vertices": [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]],
            "faces": [[0, 1, 2], [0, 2, 3]],
            # (s, t) with t up, and a texCoordIndex that mirrors the image left-right
            "tex_coords": [[0, 0], [1, 0], [1, 1], [0, 1]], "tex_coord_faces": [[1, 0, 3], [1, 3, 2]]}
    (tmp_path / "quad.obj").write_text("v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    plain = {"type": "triangles", "vertices": quad["vertices"], "faces": quad["faces"]}
    solids = [{"name": "ifs", "geometry": quad, "appearance": {"texture": "board.png"}},
              {"name": "obj", "pose": {"translation": [2, 0, 0]}, "geometry": {"type": "mesh", "url": "quad.obj"},
               "appearance": {"texture": "board.png"}},
              {"name": "default", "pose": {"translation": [4, 0, 0]}, "geometry": plain,
               "appearance": {"texture": "board.png"}}]
    # at local (0.3, 0.2): t-up coordinates (s, t) = (0.8, 0.7) -> (u, v) = (0.8, 0.3): row 1, col 3;
    # mirrored: u = 0.2 -> col 0; the default mapping: u = x + 0.5 = 0.8, v = 1 - (y + 0.5) = 0.3
    v = read_all(sim_of(tmp_path, solids, [ir("ifs", 0.3, 0.2), ir("obj", 2.3, 0.2), ir("default", 4.3, 0.2)],
                        precision))
    assert v["ifs"] == pytest.approx(expected(H, REDS[1, 0] / 255), rel=1e-9)
    assert v["obj"] == pytest.approx(expected(H, REDS[1, 3] / 255), rel=1e-9)
    assert v["default"] == pytest.approx(expected(H, REDS[1, 3] / 255), rel=1e-9)


def test_indexed_face_set_tex_coords_from_a_wbt(tmp_path: Path) -> None:
    board(tmp_path)
    (tmp_path / "w.wbt").write_text("""#VRML_SIM R2023b utf8
Solid { children [ Shape {
  appearance Appearance { texture ImageTexture { url [ "board.png" ] } }
  geometry IndexedFaceSet {
    coord Coordinate { point [ -0.5 -0.5 0, 0.5 -0.5 0, 0.5 0.5 0, -0.5 0.5 0 ] }
    texCoord TextureCoordinate { point [ 0 0, 1 0, 1 1, 0 1 ] }
    coordIndex [ 0 1 2 3 -1 ]
    texCoordIndex [ 1 0 3 9 -1 ]
  } } ] }
""")
    g = load_world(tmp_path / "w.wbt").world.solids[0].shapes[0].geometry
    assert isinstance(g, wm.Triangles)
    assert g.faces == [(0, 1, 2), (0, 2, 3)]
    # index 9 is outside texCoord: Webots reads (0.5, 0.5) there, kept as one extra coordinate
    assert g.tex_coords == [(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]
    assert g.tex_coord_faces == [(1, 0, 3), (1, 3, 4)]


def test_triangle_locator_agrees_with_brute_force() -> None:
    rng = np.random.default_rng(5)
    v = rng.uniform(-1, 1, (300, 3))
    f = rng.integers(0, 300, (400, 3))
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    loc = TriangleLocator(v, f)
    tri = rng.integers(0, len(f), 200)
    b = rng.uniform(0.05, 0.45, (200, 2))
    corners = v[f[tri]]
    p = corners[:, 0] * (1 - b.sum(1))[:, None] + corners[:, 1] * b[:, 0:1] + corners[:, 2] * b[:, 1:2]
    d = rng.normal(size=(200, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    o = p - 2.0 * d
    found, b1, b2 = loc.locate(o, d, np.full(200, 2.0))
    assert (found >= 0).all()
    same = found == tri       # another triangle may cross the same point; where it is ours, same barycentrics
    assert same.mean() > 0.9
    assert np.allclose(b1[same], b[same, 0], atol=1e-9) and np.allclose(b2[same], b[same, 1], atol=1e-9)


# ------------------------------------------------------------------ images and limits

def test_image_modes_read_as_webots(tmp_path: Path) -> None:
    """RGBA: alpha ignored (pickColor reads RGB); grey and palette images as RGB; 16-bit grey rounded."""
    rgba = tmp_path / "a.png"
    Image.fromarray(np.array([[[200, 10, 20, 0]]], dtype=np.uint8), "RGBA").save(rgba)
    assert load_image(rgba).tolist() == [[[200, 10, 20]]]
    grey = tmp_path / "g.png"
    Image.fromarray(np.array([[77]], dtype=np.uint8), "L").save(grey)
    assert load_image(grey).tolist() == [[[77, 77, 77]]]
    deep = tmp_path / "d.png"
    Image.fromarray(np.array([[65535, 32896, 0]], dtype=np.uint16)).save(deep)
    assert load_image(deep)[0, :, 0].tolist() == [255, 128, 0]
    pal = tmp_path / "p.png"
    Image.fromarray(np.array([[[9, 99, 199]]], dtype=np.uint8)).convert("P", palette=Image.Palette.ADAPTIVE).save(pal)
    assert load_image(pal).tolist() == [[[9, 99, 199]]]
    jpg = tmp_path / "j.jpg"
    Image.fromarray(np.full((8, 8, 3), 128, dtype=np.uint8)).save(jpg, quality=100)
    assert abs(int(load_image(jpg)[4, 4, 0]) - 128) <= 1


def test_alpha_is_kept_apart_for_cameras(tmp_path: Path) -> None:
    """load_alpha: an RGBA, grey-alpha or palette image with transparency, or an RGB colour key, gives
    its alpha (cameras blend with it); an alpha of 255 everywhere, RGB, grey and JPEG give None."""
    rgba = tmp_path / "a.png"
    Image.fromarray(np.array([[[200, 10, 20, 0], [1, 2, 3, 128]]], dtype=np.uint8), "RGBA").save(rgba)
    assert load_alpha(rgba).tolist() == [[0, 128]] and load_image(rgba).tolist() == [[[200, 10, 20], [1, 2, 3]]]
    opaque = tmp_path / "o.png"
    Image.fromarray(np.full((2, 2, 4), 255, dtype=np.uint8), "RGBA").save(opaque)
    assert load_alpha(opaque) is None
    la = tmp_path / "la.png"
    Image.fromarray(np.array([[[77, 10]]], dtype=np.uint8), "LA").save(la)
    assert load_alpha(la).tolist() == [[10]]
    pal = tmp_path / "p.png"
    im = Image.new("P", (2, 1))
    im.putpalette([0, 0, 0, 255, 0, 0] + [0] * 762)
    im.putpixel((1, 0), 1)
    im.save(pal, transparency=0)
    assert load_alpha(pal).tolist() == [[0, 255]] and load_image(pal).tolist() == [[[0, 0, 0], [255, 0, 0]]]
    key = tmp_path / "k.png"
    Image.fromarray(np.array([[[5, 6, 7], [9, 9, 9]]], dtype=np.uint8)).save(key, transparency=(5, 6, 7))
    assert load_alpha(key).tolist() == [[0, 255]]
    for name, mode in (("rgb.png", "RGB"), ("g.png", "L")):
        Image.new(mode, (2, 2)).save(tmp_path / name)
        assert load_alpha(tmp_path / name) is None
    Image.new("RGB", (8, 8)).save(tmp_path / "j.jpg")
    assert load_alpha(tmp_path / "j.jpg") is None


def _textured(url: str) -> dict:
    return {"solids": [{"name": "a", "geometry": {"type": "box", "size": [1, 1, 1]}, "appearance": {"texture": url}}]}


def test_bad_texture_files_are_one_clear_problem_each(tmp_path: Path) -> None:
    (tmp_path / "notimage.png").write_text("hello")
    Image.new("RGB", (2, 2)).save(tmp_path / "pic.bmp")
    (tmp_path / "sub").mkdir()
    cases = {"missing.png": "not found", "notimage.png": "is not a PNG or JPEG image",
             "pic.bmp": "is a BMP image; Webots reads PNG and JPEG only", "../outside.png": "leaves the world's folder",
             "webots://projects/a.png": "webots:// urls", "https://example.org/a.png": "only local files"}
    for url, why in cases.items():
        with pytest.raises(WorldError) as exc:
            parse_world(_textured(url), base_dir=tmp_path / ("sub" if url.startswith("..") else ""))
        (problem,) = exc.value.problems
        assert problem.path == "solids[0].appearance.texture.url" and why in problem.message, (url, problem)


def test_huge_images_are_rejected_with_the_limit(tmp_path: Path) -> None:
    from sensorium.server.world.limits import WorldLimits

    Image.new("RGB", (300, 200)).save(tmp_path / "big.png")
    small = WorldLimits(texture_pixels=50_000)
    with pytest.raises(WorldError, match=r"300x200 = 60,000 pixels, more than the limit of 50,000 .*--allow-large"):
        parse_world(_textured("big.png"), base_dir=tmp_path, limits=small)
    with pytest.raises(WorldError, match="larger than the limit of 100 bytes"):
        parse_world(_textured("big.png"), base_dir=tmp_path, limits=WorldLimits(texture_file_bytes=100))
    parse_world(_textured("big.png"), base_dir=tmp_path)
    assert WorldLimits.large().texture_pixels > WorldLimits().texture_pixels
    # an image past Pillow's own bomb guard (2 x 178,956,970 pixels; a 48 kB PNG) is judged by the
    # world's limits from its header: Pillow's message answered first, and refused what --allow-large allows
    from sensorium.server.world.textures import image_header

    Image.new("1", (20_000, 20_000)).save(tmp_path / "bomb.png", optimize=True)
    with pytest.raises(WorldError) as exc:
        parse_world(_textured("bomb.png"), base_dir=tmp_path)
    assert [p.message for p in exc.value.problems] == [
        "texture 'bomb.png' has 20000x20000 = 400,000,000 pixels, more than the limit of 16,777,216 (raise the limits "
        "with --allow-large)"]
    assert image_header(tmp_path / "bomb.png", "bomb.png") == ("PNG", 20_000, 20_000)      # nothing decoded
    assert Image.MAX_IMAGE_PIXELS is not None                                              # Pillow's guard is back


def test_tex_coord_problems_are_named(tmp_path: Path) -> None:
    g = {"type": "triangles", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "faces": [[0, 1, 2]],
         "tex_coords": [[0, 0], [1, 0]]}
    with pytest.raises(WorldError) as exc:
        parse_world({"solids": [{"name": "a", "geometry": g}]})
    assert "texture coordinate index outside 0..1: [0, 1, 2]" in str(exc.value)


# ------------------------------------------------------------------ only infra-red pays

def test_no_texture_work_without_textures_or_without_infra_red(tmp_path: Path) -> None:
    board(tmp_path)
    plain = {"name": "floor", "geometry": {"type": "plane", "size": [1, 1]}, "appearance": {"base_color": [0.5, 0.5, 0.5]}}
    sim = sim_of(tmp_path, [plain], [ir("s", 0, 0)])
    assert sim.scene.textures is None
    read_all(sim)
    assert sim.counters["texture_lookups"] == 0
    textured = {**plain, "appearance": {"texture": "board.png"}}
    others = [{**ir("g", 0, 0), "type": "generic"}, {**ir("so", 0, 0), "type": "sonar"},
              {"device": "Lidar", "name": "l", "pose": {"translation": [0, 0, H], "rotation": DOWN}},
              ir("away", 0, 0, rotation=[0, 0, 1, 0])]         # infra-red looking along the floor: no hit
    sim = sim_of(tmp_path, [textured], others)
    for _ in range(3):
        read_all(sim)
    assert sim.counters["texture_lookups"] == 0


# ------------------------------------------------------------------ ink (the Pen's paint texture)

def _stroke(sim: Simulation, origin, direction, lead: float, color, density: float) -> int:
    """One pen stroke as the Pen device makes it: the nearest visual shape along the pen's ray."""
    from sensorium.server.raycast.engine import RayKind

    o, d = np.array([origin], dtype=float), np.array([direction], dtype=float)
    h = sim.scene.engine.cast(o, d, 0.0, math.inf, kind=RayKind.VISUAL)
    assert h.shape[0] >= 0
    return sim.scene.paint(int(h.shape[0]), o[0], d[0], float(h.distance[0]), lead, color, density)


def test_ink_blends_as_webots_infra_red_test_expects(tmp_path: Path) -> None:
    """Webots' distance_sensor_infra-red test paints green (0.3), violet 0xCC33FF (0.3) and red
    (0.7) under its two sensors; its expectations follow from WbPaintTexture's blending: colour
    old/(old + new) of the old ink, density added and capped at 1, read as (1 - c)·colour·texel + c·ink."""
    sim = Simulation.from_file(_webots_ir_test_world(tmp_path))
    # NUE: y is up, the pens look down; 5 mm aside, on the texel each sensor reads (the sensors'
    # rotation of 1.5708, not pi/2, puts them a hair to the -x side of u = 0.5)
    pens = {"ds0": (-0.005, 0.07, 0.08), "ds1": (-0.005, 0.07, -0.08)}
    down = (0.0, -1.0, 0.0)
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    assert sim.counters["texture_lookups"] == 1                    # only the textured board so far
    steps = [((0, 1, 0), 0.3, 1283.6893, 1450.385), ((0xCC / 255, 0x33 / 255, 1.0), 0.3, 1252.266, 1217.675),
             ((1, 0, 0), 0.7, 1025.485, 834.98)]
    for color, density, want0, want1 in steps:
        c32 = tuple(float(np.float32(np.float32(round(c * 255)) / np.float32(255))) for c in color)   # r/255.0f
        for p in pens.values():
            assert _stroke(sim, p, down, 0.01, c32, density) >= 1
        sim.step()
        v = {d.config.name: d.value for d in sim.all_devices()}
        assert v["ds0"] == pytest.approx(want0, abs=1e-3) and v["ds1"] == pytest.approx(want1, abs=1e-3)
    # the same from the formula, with the float32 the ink is kept in
    ink_r = np.float32(0.0) * np.float32(0.5) + np.float32(0.8) * np.float32(0.5)      # after violet: 0.4
    assert float(ink_r) == pytest.approx(0.4, abs=1e-7)
    sim.scene.clear_ink()
    sim.step()
    v = {d.config.name: d.value for d in sim.all_devices()}
    assert v["ds0"] == pytest.approx(1019.3725, abs=1e-3) and v["ds1"] == pytest.approx(1172.2065, abs=1e-3)


def test_ink_layer_sizes_discs_and_atlas(tmp_path: Path) -> None:
    from sensorium.server.world.textures import InkLayer, TextureSampler, bounding_radius

    board(tmp_path)
    models = [(wm.Plane(type="plane", size=(0.15, 0.15)), None),
              (wm.Box(type="box", size=(1.0, 1.0, 1.0)), wm.Appearance(texture=wm.Texture(url="board.png"))),
              (wm.Cylinder(type="cylinder", radius=0.1, height=0.2), None),
              (wm.Cone(type="cone", bottom_radius=0.1, height=0.2), None)]
    sampler = TextureSampler(models, tmp_path)
    # an untextured plane of radius 0.106 m: 32 + 992 * 0.0106 = 42.5 texels -> the nearer power of two, 32
    assert sampler.ink_layer(0).density.shape == (32, 32)
    # a textured box: its image (4x4) times the atlas factor 4 x 2
    assert sampler.ink_layer(1).density.shape == (8, 16)
    # a cylinder of radius |(0.1, 0.1)|: 32 + 992 * 0.01414 = 46.0 -> 32 (|64 - 46| > |32 - 46|), times 2 x 2
    assert sampler.ink_layer(2).density.shape == (64, 64)
    assert bounding_radius(models[2][0]) == pytest.approx(math.hypot(0.1, 0.1))
    # a cone (WbCone::nonRecursiveTextureSizeFactor 2 x 1: the side on the left half, the base on the
    # right) of bounding radius 0.1 + 0.01/0.4 = 0.125: 32 + 992 * 0.0125 = 44.4 -> 32, times 2 x 1
    assert sampler.ink_layer(3).density.shape == (32, 64)
    assert sampler.textured[[0, 1, 2, 3, 4]].tolist() == [True, True, True, True, False]
    # a lead of 5 texels across (0.05 x 32 / 0.32): a disc of radius 2 (13 texels) around (u w, v h)
    layer = InkLayer(32, 32, 32, 0.32)
    assert layer.lead_texels(0.05) == 5
    assert layer.paint(0.5, 0.5, 0.05, (1, 0, 0), 0.5) == 13
    assert layer.density[16, 14:19].tolist() == [0.5] * 5 and layer.density[14, 15:18].tolist() == [0, 0.5, 0]
    assert layer.paint(1.2, 0.5, 0.05, (1, 0, 0), 0.5) == 0                  # outside [0, 1]: nothing
    assert layer.paint(0.5, 0.5, 0.05, (0, 0, 1), 0.75)
    assert layer.density[16, 16] == 1.0 and layer.rgb[16, 16].tolist() == pytest.approx([0.4, 0, 0.6], abs=1e-6)
    # the box paints on set 1 (the atlas) but is read on set 0, as in Webots
    top = np.array([[0.0, 0.0, 0.5]])
    uv1, _ = sampler.uv(1, top + [0, 0, 1], np.array([[0, 0, -1.0]]), np.array([1.0]), atlas=True)
    assert uv1.tolist() == [[0.625, 0.25]]


def test_few_point_paths_are_the_vector_paths() -> None:
    """Up to 8 points take plain-Python paths (plane coordinates, texel lookup): the same numbers."""
    rng = np.random.default_rng(11)
    img = rng.integers(0, 256, (5, 7, 3)).astype(np.uint8)
    special = np.array([[0, 0], [1, 1], [-1e-20, 0.5], [-1, -2], [0.5, 1.0], [3.25, -0.75], [1 - 1e-17, 0.2], [2, 0]])
    for uv in [special, rng.uniform(-3, 3, (8, 2)), rng.uniform(0, 1, (5, 2))]:
        for rs in (True, False):
            for rt in (True, False):
                t = TextureImage(img, rs, rt)
                big = np.vstack([uv] * 3)                   # > 8 points: the numpy path
                assert np.array_equal(t.red(uv), t.red(big)[:len(uv)]), (rs, rt)
    p = rng.uniform(-2, 2, (8, 3))
    assert np.array_equal(tc.plane_uv(p, (1.3, 0.7)), tc.plane_uv(np.vstack([p, p]), (1.3, 0.7))[:8])
