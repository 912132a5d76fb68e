"""COLLADA meshes and CadShape materials: our own small .dae files, written here, placed as Webots
places them (the file's <unit> and <up_axis>, then +Y turned to +Z), seen at closed-form distances
by infra-red sensors and lidars, in their materials' colours by cameras and infra-red sensors, their
diffuse textures through the file's texture coordinates; damaged or oversized files one line each."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sensorium.cli import main
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import meshes
from sensorium.server.world.cad import read_dae
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import WorldError, load_world, parse_world

HEADER = "#VRML_SIM R2023b utf8\n"


# the bounded mesh worker runs under an address-space limit below the sanitizers' shadow memory:
# under their LD_PRELOAD (the CI's sanitizer pass) it cannot start, as tests/test_build_memory.py says
bounded_worker = pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                                    reason="the mesh worker's memory limit is below the sanitizers' shadow memory")

# a cube's 8 corners and 12 triangles, each 0 or 1 per axis (scaled and shifted below)
CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
CUBE = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
        (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def dae(positions, groups, *, unit: float | None = 1.0, up: str | None = "Z_UP", materials=None,
        uv=None, matrix=None) -> str:
    """A COLLADA document: ``positions`` (n, 3); ``groups`` [(material symbol or None, triangles)] with
    triangles as vertex index triples (and the same triples into ``uv`` when given); ``materials``
    {symbol: (material id, colour (r, g, b) or an image path)}."""
    materials = materials or {}
    flat = " ".join(f"{v:.17g}" for v in np.asarray(positions, dtype=float).ravel())
    n = len(positions)
    asset = "<asset>" + (f'<unit name="u" meter="{unit}"/>' if unit is not None else "") + \
            (f"<up_axis>{up}</up_axis>" if up is not None else "") + "</asset>"
    images, effects, mats, binds = [], [], [], []
    for symbol, (mid, what) in materials.items():
        if isinstance(what, str):
            images.append(f'<image id="{mid}-img"><init_from>{what}</init_from></image>')
            diffuse = f'<texture texture="{mid}-samp" texcoord="UV"/>'
            params = (f'<newparam sid="{mid}-surf"><surface type="2D"><init_from>{mid}-img</init_from></surface>'
                      f'</newparam><newparam sid="{mid}-samp"><sampler2D><source>{mid}-surf</source></sampler2D>'
                      '</newparam>')
        else:
            diffuse, params = "<color>{} {} {} 1</color>".format(*what), ""
        effects.append(f'<effect id="{mid}-fx"><profile_COMMON>{params}<technique sid="t"><lambert><diffuse>'
                       f'{diffuse}</diffuse></lambert></technique></profile_COMMON></effect>')
        mats.append(f'<material id="{mid}"><instance_effect url="#{mid}-fx"/></material>')
        binds.append(f'<instance_material symbol="{symbol}" target="#{mid}"/>')
    inputs = '<input semantic="VERTEX" source="#v" offset="0"/>'
    uv_source = ""
    if uv is not None:
        inputs += '<input semantic="TEXCOORD" source="#t" offset="1" set="0"/>'
        uv_source = (f'<source id="t"><float_array id="ta" count="{2 * len(uv)}">'
                     + " ".join(f"{v:.17g}" for v in np.asarray(uv, dtype=float).ravel())
                     + f'</float_array><technique_common><accessor source="#ta" count="{len(uv)}" stride="2">'
                     '<param name="S" type="float"/><param name="T" type="float"/></accessor></technique_common>'
                     '</source>')
    prims = []
    for symbol, tris in groups:
        index = " ".join(f"{i} {i}" if uv is not None else f"{i}" for t in tris for i in t)
        attr = f' material="{symbol}"' if symbol else ""
        prims.append(f'<triangles{attr} count="{len(tris)}">{inputs}<p>{index}</p></triangles>')
    bind = ("<bind_material><technique_common>" + "".join(binds) + "</technique_common></bind_material>"
            if binds else "")
    m = "" if matrix is None else "<matrix>" + " ".join(f"{v:.17g}" for v in np.asarray(matrix).ravel()) + "</matrix>"
    return (f'<?xml version="1.0" encoding="utf-8"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" '
            f'version="1.4.1">{asset}'
            f'<library_images>{"".join(images)}</library_images><library_effects>{"".join(effects)}</library_effects>'
            f'<library_materials>{"".join(mats)}</library_materials><library_geometries>'
            f'<geometry id="g" name="body"><mesh><source id="p"><float_array id="pa" count="{3 * n}">{flat}'
            f'</float_array><technique_common><accessor source="#pa" count="{n}" stride="3"><param name="X" '
            'type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
            f'</technique_common></source>{uv_source}<vertices id="v"><input semantic="POSITION" source="#p"/>'
            f'</vertices>{"".join(prims)}</mesh></geometry></library_geometries>'
            f'<library_visual_scenes><visual_scene id="s"><node id="n">{m}<instance_geometry url="#g">{bind}'
            '</instance_geometry></node></visual_scene></library_visual_scenes>'
            '<scene><instance_visual_scene url="#s"/></scene></COLLADA>\n')


def cube_dae(up: str, unit: float, colour=(0.5, 0.25, 1.0)) -> str:
    """A 1 m cube standing on the ground (0 ≤ up ≤ 1 m), centred on the up axis, in ``unit``s."""
    c = CORNERS - 0.5
    axis = {"X_UP": 0, "Y_UP": 1, "Z_UP": 2}[up]
    c[:, axis] += 0.5
    return dae(c / unit, [("m", CUBE)], unit=unit, up=up, materials={"m": ("paint", colour)})


def read_all(sim: Simulation) -> dict[str, float]:
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    return {d.config.name: d.value for d in sim.all_devices() if hasattr(d, "value")}


def expected(d: float, red: float) -> float:
    """An infra-red reading at distance d over a surface of red ``red`` (the LUT is 1000/m)."""
    return 1000.0 * d / (0.2 + 0.8 * red)


def wbt(tmp_path: Path, body: str, name: str = "w.wbt") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + body)
    return p


# ------------------------------------------------------------------ placement: unit and up axis

@pytest.mark.parametrize(("up", "unit"), [("Z_UP", 1.0), ("Y_UP", 0.01), ("X_UP", 0.001), ("Y_UP", 1.0)])
def test_unit_and_up_axis_place_the_cube_as_webots(tmp_path: Path, up: str, unit: float) -> None:
    (tmp_path / "cube.dae").write_text(cube_dae(up, unit))
    mesh = meshes.load_mesh(tmp_path / "cube.dae")
    np.testing.assert_allclose(mesh.vertices.min(axis=0), [-0.5, -0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(mesh.vertices.max(axis=0), [0.5, 0.5, 1.0], atol=1e-12)
    assert len(mesh.faces) == 12 and mesh.closed


def test_y_up_turns_each_axis_as_webots(tmp_path: Path) -> None:
    """Y_UP (COLLADA's default, also with no <up_axis>): (x, y, z) → (x, −z, y); X_UP: (−y, −z, x)."""
    tri = [[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    for up, want in (("Y_UP", [1.0, -3.0, 2.0]), (None, [1.0, -3.0, 2.0]), ("X_UP", [-2.0, -3.0, 1.0]),
                     ("Z_UP", [1.0, 2.0, 3.0])):
        p = tmp_path / f"{up}.dae"
        p.write_text(dae(tri, [(None, [(0, 1, 2)])], up=up, unit=None))
        np.testing.assert_allclose(read_dae(str(p)).parts[0].vertices[0], want)


# ------------------------------------------------------------------ sensors through the pipeline

@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_an_infra_red_sensor_meets_the_cm_cube_at_the_closed_form_distance(tmp_path: Path, precision: str) -> None:
    """A cube of 100 cm (Y_UP, unit 0.01) is 1 m tall once placed: a sensor 2 m up looking down
    reads d = 1 m, over the file's material's red 0.5 (its own appearance: the world gives none)."""
    (tmp_path / "cube.dae").write_text(cube_dae("Y_UP", 0.01))
    p = wbt(tmp_path, 'Solid { name "box" children [ CadShape { url [ "cube.dae" ] } ] }\n'
                      'Robot { name "r" children [ DistanceSensor { name "ir" translation 0.2 0.1 2 '
                      'rotation 0 1 0 1.5707963267948966 type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    w = load_world(p)
    (shape,) = w.world.solids[0].shapes
    assert (shape.geometry.type, shape.geometry.url, shape.geometry.material_index) == ("mesh", "cube.dae", 0)
    assert shape.appearance.base_color == (0.5, 0.25, 1.0) and shape.seen_by == "visual"
    assert w.losses == ()
    values = read_all(Simulation(w, precision=precision))
    assert values["ir"] == pytest.approx(expected(1.0, 0.5), rel=1e-9 if precision == "exact" else 2e-3)


def test_a_lidar_sees_the_cube_of_a_mesh_node_at_its_faces(tmp_path: Path) -> None:
    """A Mesh node with a .dae (also in a boundingObject): a one-beam lidar 3 m from the cube's face."""
    (tmp_path / "cube.dae").write_text(cube_dae("Z_UP", 0.001))
    p = wbt(tmp_path, 'Solid { name "box" translation 4 0 0 children [ Shape { geometry DEF M Mesh { url [ "cube.dae" ] } } ] '
                      'boundingObject USE M }\n'
                      'Robot { name "r" children [ Lidar { name "l" translation 0 0 0.5 horizontalResolution 1 '
                      'fieldOfView 0.1 numberOfLayers 1 maxRange 10 } ] }\n')
    w = load_world(p)
    sim = Simulation(w, precision="exact")
    lidar = sim.device("r/l")
    lidar.enable(32)
    sim.step()
    assert np.asarray(lidar.range_image).ravel()[0] == pytest.approx(3.5, abs=1e-9)


def test_a_camera_sees_each_material_in_its_colour(tmp_path: Path) -> None:
    """Two materials in one file: two shapes, each in its diffuse colour (ambient light 1: a pixel is
    the tone-mapped colour itself)."""
    quad = [[2.0, -1.0, -1.0], [2.0, 1.0, -1.0], [2.0, 1.0, 1.0], [2.0, -1.0, 1.0]]
    left, right = [(0, 1, 2)], [(0, 2, 3)]
    (tmp_path / "wall.dae").write_text(dae(quad, [("a", left), ("b", right)], materials={
        "a": ("green", (0.1, 0.8, 0.3)), "b": ("blue", (0.2, 0.3, 0.9))}))
    p = wbt(tmp_path, 'DirectionalLight { direction 1 0 0 intensity 0 ambientIntensity 1 }\n'
                      'Solid { children [ CadShape { url [ "wall.dae" ] } ] }\n'
                      'Robot { name "r" children [ Camera { name "cam" width 2 height 1 fieldOfView 0.5 } ] }\n')
    w = load_world(p)
    assert [(s.geometry.material_index, s.appearance.base_color) for s in w.world.solids[0].shapes] == [
        (0, (0.2, 0.3, 0.9)), (1, (0.1, 0.8, 0.3))]       # numbered by material id: "blue" < "green"
    sim = Simulation(w, precision="exact")
    cam = sim.device("r/cam")
    cam.enable(32)
    sim.step()
    img = cam.image[:, :, [2, 1, 0]].astype(np.int64)

    def tone(c):
        return np.floor(255.0 * (1.0 - np.exp(-np.asarray(c))) ** (1.0 / 2.2) + 0.5).astype(np.int64)

    # the left pixel looks towards +y: on the centre row (z = 0) it meets y > 0, inside the triangle
    # (0, 1, 2) (z ≤ y: material "a", green); the right one y < 0, inside (0, 2, 3) (blue)
    np.testing.assert_array_equal(img[0, 0], tone([0.1, 0.8, 0.3]))
    np.testing.assert_array_equal(img[0, 1], tone([0.2, 0.3, 0.9]))


# 4 x 4 texels with distinct reds (row 0 is the image's top row)
REDS = np.array([[0, 17, 34, 51], [68, 85, 102, 113], [136, 153, 170, 187], [204, 221, 238, 255]])


def save_board(path: Path) -> None:
    """The 4 x 4 test texture: red REDS, green 255 - REDS, blue 7."""
    Image.fromarray(np.stack([REDS, 255 - REDS, np.full_like(REDS, 7)], axis=-1).astype(np.uint8)).save(path)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_textured_quad_reads_the_texel_under_each_hit(tmp_path: Path, precision: str) -> None:
    """A CadShape whose material's diffuse is an image beside the .dae (in a sub-folder): infra-red
    sensors read the texel at the file's texture coordinates (t up, as assimp's FlipUVs)."""
    (tmp_path / "parts" / "img").mkdir(parents=True)
    save_board(tmp_path / "parts" / "img" / "board.png")
    quad = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
    (tmp_path / "parts" / "quad.dae").write_text(dae(quad, [("m", [(0, 1, 2), (0, 2, 3)])], uv=[[0, 0], [1, 0], [1, 1], [0, 1]],
                                                     materials={"m": ("board", "img/board.png")}))
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "parts/quad.dae" ] } ] }\n'
                      'Robot { name "r" children [\n'
                      '  DistanceSensor { name "a" translation 0.3 0.2 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] }\n'
                      '  DistanceSensor { name "b" translation -0.4 -0.1 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    w = load_world(p)
    (shape,) = w.world.solids[0].shapes
    assert shape.appearance.texture.url == "parts/img/board.png" and shape.appearance.base_color == (1.0, 1.0, 1.0)
    v = read_all(Simulation(w, precision=precision))
    # (x, y) → (s, t) = (x + 0.5, y + 0.5) → image column s·4, row (1 − t)·4
    assert v["a"] == pytest.approx(expected(0.0625, REDS[1, 3] / 255), rel=1e-9)
    assert v["b"] == pytest.approx(expected(0.0625, REDS[2, 0] / 255), rel=1e-9)


def test_a_mesh_node_takes_one_material_or_one_geometry(tmp_path: Path) -> None:
    """Webots' Mesh.materialIndex and Mesh.name (COLLADA only): only those triangles."""
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    (tmp_path / "two.dae").write_text(dae(quad, [("a", [(0, 1, 2)]), ("b", [(0, 2, 3), (0, 1, 3)])], materials={
        "a": ("m1", (1, 0, 0)), "b": ("m0", (0, 1, 0))}))
    p = wbt(tmp_path, 'Solid { children [ Shape { geometry Mesh { url [ "two.dae" ] materialIndex 1 } }\n'
                      '  Shape { geometry Mesh { url [ "two.dae" ] materialIndex 0 name "body" } }\n'
                      '  Shape { geometry Mesh { url [ "two.dae" ] } } ] }\n')
    w = load_world(p)
    shapes = w.world.solids[0].shapes
    assert [(s.geometry.material_index, s.geometry.name) for s in shapes] == [(1, ""), (0, "body"), (-1, "")]
    sizes = [len(meshes.load_mesh(tmp_path / "two.dae", material=s.geometry.material_index,
                                  name=s.geometry.name).faces) for s in shapes]
    assert sizes == [1, 2, 3]       # m1 (index 1): the one triangle of symbol "a"
    with pytest.raises(WorldError, match=r"no triangles of material index 5"):
        parse_world({"solids": [{"name": "s", "geometry": {"type": "mesh", "url": "two.dae", "material_index": 5}}]},
                    base_dir=tmp_path)
    with pytest.raises(WorldError, match=r"no triangles in geometry 'wheel'"):
        parse_world({"solids": [{"name": "s", "geometry": {"type": "mesh", "url": "two.dae", "name": "wheel"}}]},
                    base_dir=tmp_path)


# ------------------------------------------------------------------ bad files, limits, validate

DAMAGED = {
    "truncated": lambda good: good[: len(good) // 2],
    "not xml": lambda good: "solid nothing\n",
    "bad numbers": lambda good: good.replace('<float_array id="pa" count="24">', '<float_array id="pa" count="24">x y '),
    "index out of range": lambda good: good.replace("<p>0 1 3 ", "<p>0 1 99 "),
    "no geometry": lambda good: good[: good.index("<library_geometries>")] + "</COLLADA>\n",
}


@pytest.mark.parametrize("damage", sorted(DAMAGED))
def test_a_damaged_dae_is_one_line_naming_the_file_and_validate_exits_1(tmp_path: Path, damage: str, capsys) -> None:
    (tmp_path / "cube.dae").write_text(DAMAGED[damage](cube_dae("Z_UP", 1.0)))
    p = wbt(tmp_path, 'Solid { name "box" children [ CadShape { url [ "cube.dae" ] } ] }\n')
    assert main(["validate", str(p)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = [x for x in err.splitlines() if "cube.dae" in x]
    assert len(lines) == 1 and ("cannot read COLLADA mesh cube.dae: " in lines[0] or "no triangles" in lines[0]), err
    assert f"{p}: line 2, column 31 (CadShape, " in lines[0]


def test_entity_bombs_and_external_entities_are_one_problem(tmp_path: Path) -> None:
    """XML entities nested to a billion characters, or naming a file of the machine: one line, quickly."""
    lol = '<?xml version="1.0"?>\n<!DOCTYPE COLLADA [\n<!ENTITY e0 "' + "a" * 80 + '">\n'
    for i in range(1, 10):
        lol += f'<!ENTITY e{i} "' + f"&e{i - 1};" * 10 + '">\n'
    body = ('<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1"><asset><contributor>'
            '<author>{}</author></contributor></asset></COLLADA>\n')
    (tmp_path / "lol.dae").write_text(lol + "]>\n" + body.format("&e9;"))
    (tmp_path / "xxe.dae").write_text('<?xml version="1.0"?>\n<!DOCTYPE COLLADA [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
                                      + body.format("&x;"))
    for name in ("lol.dae", "xxe.dae"):
        with pytest.raises(WorldError) as info:
            parse_world({"solids": [{"name": "s", "geometry": {"type": "mesh", "url": name}}]}, base_dir=tmp_path)
        (problem,) = info.value.problems
        assert problem.message.startswith(f"cannot read COLLADA mesh {name}: ") and "root:" not in problem.message


def test_validate_of_a_world_with_a_dae_cad_shape_exits_0(tmp_path: Path, capsys) -> None:
    (tmp_path / "cube.dae").write_text(cube_dae("Y_UP", 0.01))
    p = wbt(tmp_path, 'Solid { name "box" children [ CadShape { url [ "cube.dae" ] } ] }\n'
                      'Robot { name "r" children [ DistanceSensor { name "ir" translation 0 0 2 } ] }\n')
    assert main(["validate", str(p)]) == 0
    assert capsys.readouterr().out.strip() == f"{p}: OK"


def test_triangles_count_in_the_worlds_budget(tmp_path: Path) -> None:
    (tmp_path / "cube.dae").write_text(cube_dae("Z_UP", 1.0))
    data = {"solids": [{"name": "s", "geometry": {"type": "mesh", "url": "cube.dae"}}]}
    with pytest.raises(WorldError, match=r"more than 11 triangles in its scene, the world's limit"):
        parse_world(data, base_dir=tmp_path, limits=WorldLimits(triangles=11))
    parse_world(data, base_dir=tmp_path, limits=WorldLimits(triangles=12))


@bounded_worker
def test_a_large_dae_is_read_in_the_bounded_worker_with_the_same_triangles(tmp_path: Path, monkeypatch) -> None:
    """Files above meshes.IN_PROCESS_BYTES are read in a worker under a memory limit (here every file)."""
    (tmp_path / "cube.dae").write_text(cube_dae("Y_UP", 0.01))
    inline = meshes.load_mesh(tmp_path / "cube.dae")
    monkeypatch.setattr(meshes, "IN_PROCESS_BYTES", 0)
    meshes._CACHE.clear()
    worker = meshes.load_mesh(tmp_path / "cube.dae", (2.0, 2.0, 2.0))
    np.testing.assert_allclose(worker.vertices, inline.vertices * 2.0)
    np.testing.assert_array_equal(worker.faces, inline.faces)
    assert worker.closed
    (tmp_path / "bad.dae").write_text(cube_dae("Z_UP", 1.0)[:300])
    with pytest.raises(meshes.MeshFileError, match=r"cannot read COLLADA mesh .*bad\.dae: XML Parsing Error"):
        meshes.load_mesh(tmp_path / "bad.dae")
    with pytest.raises(meshes.MeshFileError, match=r"more than 5 triangles in its scene, the world's limit"):
        meshes.load_mesh(tmp_path / "cube.dae", (3.0, 3.0, 3.0), max_triangles=5)
    # an OBJ file's faces of one material (a CadShape's) go through the same reader there
    (tmp_path / "two.obj").write_text("mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "usemtl b\nf 1 2 3\nusemtl a\nf 1 3 4\nf 1 2 4\n")
    (tmp_path / "two.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n")
    assert [len(meshes.load_mesh(tmp_path / "two.obj", material=i).faces) for i in (0, 1)] == [2, 1]
    assert len(meshes.load_mesh(tmp_path / "two.obj").faces) == 3
    # a CadShape's materials are read there too
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "cube.dae" ] } CadShape { url [ "two.obj" ] } ] }\n')
    assert [(s.geometry.url, s.geometry.material_index, s.appearance.base_color)
            for s in load_world(p).world.solids[0].shapes] == [
        ("cube.dae", 0, (0.5, 0.25, 1.0)), ("two.obj", 0, (1.0, 0.0, 0.0)), ("two.obj", 1, (0.0, 1.0, 0.0))]
    with pytest.raises(meshes.MeshFileError, match=r"cannot read COLLADA mesh .*bad\.dae: XML Parsing Error"):
        meshes.file_materials(tmp_path / "bad.dae", "dae")


def test_a_dae_without_suffix_is_known_by_its_content(tmp_path: Path) -> None:
    """Webots' asset cache names files by a hash, without a suffix."""
    (tmp_path / "3f2a9c").write_text(cube_dae("Y_UP", 0.01))
    assert meshes.mesh_format(tmp_path / "3f2a9c") == "dae"
    assert meshes.load_mesh(tmp_path / "3f2a9c").vertices[:, 2].max() == pytest.approx(1.0)


def test_fbx_stays_unread_and_said(tmp_path: Path) -> None:
    (tmp_path / "part.fbx").write_bytes(b"Kaydara FBX Binary  \x00")
    p = wbt(tmp_path, 'Solid { name "s" children [ CadShape { url [ "part.fbx" ] } ] }\n')
    (loss,) = load_world(p).losses
    assert "the .fbx format is not read here" in loss.why


# ------------------------------------------------------------------ OBJ + MTL materials (CadShape)

@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_an_obj_cad_shape_takes_its_mtl_materials(tmp_path: Path, precision: str) -> None:
    """A CadShape's OBJ file with an .mtl: one shape per material its faces use, Kd as the colour,
    1 − d as the transparency, map_Kd (beside the file) through the file's vt; Kd multiplies the texel
    (Webots' baseColor × baseColorMap)."""
    (tmp_path / "img").mkdir()
    save_board(tmp_path / "img" / "board.png")
    (tmp_path / "two.obj").write_text("mtllib two.mtl\n"
                                      "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
                                      "v 5 0 0\nv 6 0 0\nv 5 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                      "usemtl red\nf 1/1 2/2 3/3\nusemtl tex\nf 1/1 3/3 4/4\n"
                                      "usemtl glass\nf 5/1 6/2 7/3\n")
    (tmp_path / "two.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n\nnewmtl tex\nKd 0.5 0.5 0.5\n"
                                      "map_Kd -s 1 1 1 img/board.png\nnewmtl glass\nKd 0.2 0.2 0.2\nd 0.4\n")
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "two.obj" ] } ] }\n'
                      'Robot { name "r" children [\n'
                      '  DistanceSensor { name "a" translation 0.3 -0.2 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] }\n'
                      '  DistanceSensor { name "b" translation -0.4 0.1 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    w = load_world(p)
    shapes = w.world.solids[0].shapes
    assert [(s.geometry.material_index, s.appearance.base_color, s.appearance.transparency,
             s.appearance.texture.url if s.appearance.texture else None) for s in shapes] == [
        (0, (0.2, 0.2, 0.2), pytest.approx(0.6), None), (1, (0.8, 0.1, 0.1), 0.0, None),
        (2, (0.5, 0.5, 0.5), 0.0, "img/board.png")]          # glass, red, tex: the names sorted
    v = read_all(Simulation(w, precision=precision))
    assert v["a"] == pytest.approx(expected(0.0625, 0.8), rel=1e-9)
    # (x, y) = (-0.4, 0.1) → (s, t) = (0.1, 0.6) → column 0, row 1
    assert v["b"] == pytest.approx(expected(0.0625, 0.5 * REDS[1, 0] / 255), rel=1e-9)


def test_an_obj_without_materials_stays_one_white_mesh(tmp_path: Path) -> None:
    """No .mtl (or one that is missing, or outside the OBJ file's folder: not read): the file as before,
    one mesh, white (as Webots draws it)."""
    (tmp_path / "w").mkdir()
    (tmp_path / "outside.mtl").write_text("newmtl x\nKd 1 0 0\n")
    (tmp_path / "w" / "part.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "w" / "gone.obj").write_text("mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n")
    (tmp_path / "w" / "out.obj").write_text("mtllib ../outside.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n")
    p = wbt(tmp_path / "w", 'Solid { children [ CadShape { url [ "part.obj" ] } CadShape { url [ "gone.obj" ] } '
                            'CadShape { url [ "out.obj" ] } ] }\n')
    shapes = load_world(p).world.solids[0].shapes
    assert [(s.geometry.url, s.geometry.material_index, s.appearance.base_color if s.appearance else None)
            for s in shapes] == [("part.obj", -1, None), ("gone.obj", -1, None), ("out.obj", -1, None)]
    from sensorium.server.world.cad import _mtl_library

    (tmp_path / "w" / "in.mtl").write_text("newmtl y\nKd 0 1 0\n")
    (tmp_path / "w" / "both.obj").write_text("mtllib ../outside.mtl in.mtl\nv 0 0 0\n")
    assert list(_mtl_library(str(tmp_path / "w" / "both.obj"))) == ["y"]


def test_a_proto_and_a_webots_cad_shape_read_their_textures_beside_them(tmp_path: Path, monkeypatch) -> None:
    """A PROTO's CadShape url is relative to the PROTO file, a webots:// one names the installation's
    file; each material's image is relative to its .dae and read in place (read only), as the .dae."""
    from _protos import proto_file, webots_home, world_file

    quad = [[-0.1, -0.1, 0.0], [0.1, -0.1, 0.0], [0.1, 0.1, 0.0], [-0.1, 0.1, 0.0]]
    home = webots_home(tmp_path / "webots", monkeypatch)
    (home / "projects" / "meshes" / "tex").mkdir(parents=True)
    Image.new("RGB", (4, 4), (51, 0, 0)).save(home / "projects" / "meshes" / "tex" / "dark.png")
    (home / "projects" / "meshes" / "dark.dae").write_text(dae(
        quad, [("m", [(0, 1, 2), (0, 2, 3)])], uv=[[0, 0], [1, 0], [1, 1], [0, 1]], materials={"m": ("d", "tex/dark.png")}))
    protos = tmp_path / "project" / "protos"
    (protos / "meshes").mkdir(parents=True)
    Image.new("RGB", (4, 4), (153, 0, 0)).save(protos / "meshes" / "mid.png")
    (protos / "meshes" / "mid.dae").write_text(dae(
        quad, [("m", [(0, 1, 2), (0, 2, 3)])], uv=[[0, 0], [1, 0], [1, 1], [0, 1]], materials={"m": ("d", "mid.png")}))
    proto_file(protos, "Tiles", """[ field SFString name "tiles" ]
{ Solid { name IS name children [ CadShape { url [ "meshes/mid.dae" ] }
    Pose { translation 0.5 0 0 children [ CadShape { url [ "webots://projects/meshes/dark.dae" ] } ] } ] } }""")
    w = world_file(tmp_path / "project" / "worlds", """Tiles { }
Robot { name "r" children [
  DistanceSensor { translation 0 0 0.01 rotation 0 1 0 1.5707963267948966 name "a" type "infra-red" lookupTable [ 0 0 0, 1 1000 0 ] }
  DistanceSensor { translation 0.5 0 0.01 rotation 0 1 0 1.5707963267948966 name "b" type "infra-red" lookupTable [ 0 0 0, 1 1000 0 ] } ] }
""", ["../protos/Tiles.proto"])
    loaded = load_world(w)
    assert not [m for m in loaded.warnings if "texture" in m] and loaded.losses == ()
    assert [p.appearance.texture.url for p in loaded.world.solids[0].shapes] == [
        str((protos / "meshes" / "mid.png").resolve()), str((home / "projects/meshes/tex/dark.png").resolve())]
    v = read_all(Simulation(loaded))
    assert v["a"] == pytest.approx(1000 * 0.01 / (0.2 + 0.8 * 153 / 255), rel=1e-9)
    assert v["b"] == pytest.approx(1000 * 0.01 / (0.2 + 0.8 * 51 / 255), rel=1e-9)


def test_a_file_of_many_materials_over_the_limit_is_one_problem(tmp_path: Path) -> None:
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    (tmp_path / "two.dae").write_text(dae(quad, [("a", [(0, 1, 2)]), ("b", [(0, 2, 3)])], materials={
        "a": ("m0", (1, 0, 0)), "b": ("m1", (0, 1, 0))}))
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "two.dae" ] } ] }\n')
    assert len(load_world(p).world.solids[0].shapes) == 2
    meshes._CACHE.clear()        # (read again under the limit, as a first load would)
    with pytest.raises(WorldError) as info:
        load_world(p, limits=WorldLimits(triangles=1))
    (problem,) = info.value.problems
    assert "cannot read COLLADA mesh two.dae: more than 1 triangles in its scene" in problem.message


def test_a_material_texture_missing_or_outside_the_folder_is_a_note_not_a_problem(tmp_path: Path) -> None:
    """Webots draws such a material without its image: the shape keeps its (white) colour, one summary
    line says the texture was not loaded, validate passes."""
    Image.new("RGB", (4, 4), (10, 0, 0)).save(tmp_path / "secret.png")
    (tmp_path / "w").mkdir()
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    (tmp_path / "w" / "q.dae").write_text(dae(quad, [("a", [(0, 1, 2)]), ("b", [(0, 2, 3)])], uv=[[0, 0], [1, 0], [1, 1], [0, 1]],
                                              materials={"a": ("m0", "../secret.png"), "b": ("m1", "gone.png")}))
    p = wbt(tmp_path / "w", 'Solid { children [ CadShape { url [ "q.dae" ] } ] }\n')
    w = load_world(p)
    assert [(s.appearance.base_color, s.appearance.texture) for s in w.world.solids[0].shapes] == [
        ((1.0, 1.0, 1.0), None), ((1.0, 1.0, 1.0), None)]
    said = [x for x in w.warnings if "texture" in x]
    assert len(said) == 1 and "outside the world's folder" in said[0], said
    assert w.losses == ()


@pytest.mark.parametrize(("effect", "want"), [
    ("", 0.0),                                                                          # opaque
    ('<transparent opaque="A_ONE"><color>1 1 1 0.25</color></transparent>', 0.75),      # alpha times 1
    ('<transparent><color>0 0 0 1</color></transparent><transparency><float>0.4</float></transparency>', 0.6),
    ('<transparent opaque="RGB_ZERO"><color>0.2 0.2 0.2 1</color></transparent>'
     '<transparency><float>1</float></transparency>', 0.2),                              # 1 − luminance
    ("<transparency><float>0.5</float></transparency>", 0.5),                          # alone
])
def test_transparency_as_assimp_reads_a_collada_effect(tmp_path: Path, effect: str, want: float) -> None:
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0]]
    text = dae(quad, [("a", [(0, 1, 2)])], materials={"a": ("m", (0.5, 0.5, 0.5))})
    (tmp_path / "t.dae").write_text(text.replace("</diffuse>", "</diffuse>" + effect))
    (m,) = read_dae(str(tmp_path / "t.dae")).materials
    assert (m.diffuse, m.transparency) == ((0.5, 0.5, 0.5), pytest.approx(want, abs=1e-6))


@bounded_worker
def test_materials_too_large_for_the_workers_memory_are_said_not_silently_white(tmp_path: Path, monkeypatch) -> None:
    """A CadShape whose materials the worker could not read within its memory (its geometry may still
    load under --allow-large) is converted with one note saying it is seen white; a damaged file is
    said once, by the Mesh it becomes, not twice."""
    (tmp_path / "cube.dae").write_text(cube_dae("Z_UP", 1.0))
    monkeypatch.setattr(meshes, "IN_PROCESS_BYTES", 0)
    monkeypatch.setattr(meshes, "_worker_header", lambda *a: {"ok": False, "kind": "memory", "error": "out of memory"})
    with pytest.raises(meshes.MeshMemoryError, match="its materials take more than"):
        meshes.file_materials(tmp_path / "cube.dae", "dae")
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "cube.dae" ] } ] }\n')
    w = load_world(p)
    said = [x for x in w.warnings if "materials" in x]
    assert len(said) == 1 and "the materials of 'cube.dae' are not read (its materials take more than" in said[0], said
    assert [s.appearance for s in w.world.solids[0].shapes] == [None]     # no appearance: seen white
    assert w.losses == ()


@bounded_worker
def test_a_large_cad_shape_of_many_materials_is_read_once_for_all_of_them(tmp_path: Path, monkeypatch) -> None:
    """A CadShape asks for each material's triangles: a file read in the worker (Webots' Panda links
    are ~1 MB of a dozen materials each) is read once for all of them, not once a material, with the
    same triangles as in process; a material whose triangles are missing is still one line."""
    colours = {f"m{i}": (f"paint{i}", (0.1 * i, 0.5, 0.5)) for i in range(3)}
    groups = [(f"m{i}", CUBE[4 * i:4 * i + 4]) for i in range(3)]
    (tmp_path / "three.dae").write_text(dae(CORNERS, groups, materials=colours))
    inline = [meshes.load_mesh(tmp_path / "three.dae", (1.0, 2.0, 3.0), material=i) for i in range(3)]
    meshes._CACHE.clear()
    monkeypatch.setattr(meshes, "IN_PROCESS_BYTES", 0)
    runs = []
    real = meshes._run_worker
    monkeypatch.setattr(meshes, "_run_worker", lambda *a: runs.append(a[-1]) or real(*a))
    worker = [meshes.load_mesh(tmp_path / "three.dae", (1.0, 2.0, 3.0), material=i) for i in (2, 0, 1)]
    assert runs == [(meshes.ALL_MATERIALS, "")]
    for a, b in zip(inline, [worker[1], worker[2], worker[0]], strict=True):
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.faces, b.faces)
        assert a.closed is b.closed is False
    with pytest.raises(meshes.MeshFileError, match=r"has no triangles of material index 3"):
        meshes.load_mesh(tmp_path / "three.dae", (1.0, 1.0, 1.0), material=3)
    meshes._CACHE.clear()
    runs.clear()
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "three.dae" ] } ] }\n')
    shapes = load_world(p).world.solids[0].shapes
    assert [(s.geometry.material_index, s.appearance.base_color) for s in shapes] == [
        (0, (0.0, 0.5, 0.5)), (1, (0.1, 0.5, 0.5)), (2, (0.2, 0.5, 0.5))]
    assert runs == [(meshes.ALL_MATERIALS, "")]


def test_texture_coordinates_are_the_lowest_set_whatever_the_order_of_the_inputs(tmp_path: Path) -> None:
    """A file with two TEXCOORD sets (a lightmap set 1 written before the texture's set 0, as some
    exporters write them): the texture is mapped by set 0, assimp's channel 0 that Webots uses, not
    by the first input written."""
    (tmp_path / "img").mkdir()
    save_board(tmp_path / "img" / "board.png")
    quad = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
    text = dae(quad, [("m", [(0, 1, 2), (0, 2, 3)])], uv=[[0, 0], [1, 0], [1, 1], [0, 1]],
               materials={"m": ("board", "img/board.png")})
    lightmap = ('<source id="t1"><float_array id="t1a" count="8">0.9 0.1 0.9 0.1 0.9 0.1 0.9 0.1</float_array>'
                '<technique_common><accessor source="#t1a" count="4" stride="2"><param name="S" type="float"/>'
                '<param name="T" type="float"/></accessor></technique_common></source>')
    set0 = '<input semantic="TEXCOORD" source="#t" offset="1" set="0"/>'
    assert set0 in text and '<source id="t">' in text
    text = text.replace('<source id="t">', lightmap + '<source id="t">').replace(
        set0, '<input semantic="TEXCOORD" source="#t1" offset="1" set="1"/>' + set0)
    (tmp_path / "quad.dae").write_text(text)
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "quad.dae" ] } ] }\n'
                      'Robot { name "r" children [\n'
                      '  DistanceSensor { name "a" translation 0.3 0.2 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    v = read_all(Simulation(load_world(p), precision="exact"))
    assert v["a"] == pytest.approx(expected(0.0625, REDS[1, 3] / 255), rel=1e-9)   # set 1 would read REDS[3, 3]


def test_mtl_files_as_blender_and_windows_tools_write_them(tmp_path: Path) -> None:
    """What real .mtl files hold: a material Blender names ``None``, an image path with spaces after
    texture options (a Windows export's ``My Textures/board 1.png``; the whole rest of the line is the
    file, as assimp reads it), and ``Tr`` (1 − opacity) instead of ``d``: the texel under the sensor
    is read and the glass is 25 % transparent."""
    (tmp_path / "My Textures").mkdir()
    save_board(tmp_path / "My Textures" / "board 1.png")
    (tmp_path / "part.obj").write_text("mtllib part.mtl\n"
                                       "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nv 5 0 0\nv 6 0 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                       "usemtl None\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\nusemtl glass\nf 5/1 6/2 7/3\n"
                                       "v 5 1 0\n")
    (tmp_path / "part.mtl").write_text("# Blender MTL File: 'None'\nnewmtl None\nKd 1 1 1\n"
                                       "map_Kd -bm 1.0 -s 1 1 1 My Textures/board 1.png  \n"
                                       "newmtl glass\nKd 0.2 0.2 0.2\nTr 0.25\n")
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "part.obj" ] } ] }\n'
                      'Robot { name "r" children [\n'
                      '  DistanceSensor { name "b" translation -0.4 0.1 0.0625 rotation 0 1 0 1.5707963267948966 '
                      'type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    w = load_world(p)
    assert [(s.appearance.base_color, s.appearance.transparency,
             s.appearance.texture.url if s.appearance.texture else None) for s in w.world.solids[0].shapes] == [
        ((1.0, 1.0, 1.0), 0.0, "My Textures/board 1.png"), ((0.2, 0.2, 0.2), pytest.approx(0.25), None)]
    assert not [x for x in w.warnings if "texture" in x], w.warnings
    v = read_all(Simulation(w, precision="exact"))
    assert v["b"] == pytest.approx(expected(0.0625, REDS[1, 0] / 255), rel=1e-9)   # (s, t) = (0.1, 0.6)


@bounded_worker
def test_convert_reads_a_large_cad_shapes_materials_once(tmp_path: Path, monkeypatch, capsys) -> None:
    """`sensorium convert` converts a .wbt world twice (to check it, then to write it): a large
    CadShape file's materials are read by the worker once, and its triangles once, not once a
    conversion and once a material."""
    colours = {f"m{i}": (f"paint{i}", (0.1 * i, 0.5, 0.5)) for i in range(3)}
    (tmp_path / "three.dae").write_text(dae(CORNERS, [(f"m{i}", CUBE[4 * i:4 * i + 4]) for i in range(3)],
                                            materials=colours))
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "three.dae" ] } ] }\n')
    monkeypatch.setattr(meshes, "IN_PROCESS_BYTES", 0)
    runs: list[str] = []
    header, triangles = meshes._worker_header, meshes._run_worker
    monkeypatch.setattr(meshes, "_worker_header", lambda *a: runs.append("materials") or header(*a))
    monkeypatch.setattr(meshes, "_run_worker", lambda *a: runs.append("triangles") or triangles(*a))
    assert main(["convert", str(p), str(tmp_path / "w.yaml")]) == 0
    assert runs == ["materials", "triangles"]
    assert (tmp_path / "w.yaml").read_text().count("material_index") == 3


def skinned(text: str, bind_shape) -> str:
    """A ``dae()`` document whose geometry is instanced through a skin controller (an armature's
    mesh, as Blender exports a rigged model), its bind shape matrix ``bind_shape``."""
    m = " ".join(f"{v:.17g}" for v in np.asarray(bind_shape, dtype=float).ravel())
    controller = (
        f'<library_controllers><controller id="c"><skin source="#g"><bind_shape_matrix>{m}</bind_shape_matrix>'
        '<source id="jn"><Name_array id="jna" count="1">bone</Name_array><technique_common><accessor source="#jna" '
        'count="1" stride="1"><param name="JOINT" type="name"/></accessor></technique_common></source>'
        '<source id="ib"><float_array id="iba" count="16">1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</float_array>'
        '<technique_common><accessor source="#iba" count="1" stride="16"><param name="TRANSFORM" type="float4x4"/>'
        '</accessor></technique_common></source><source id="sw"><float_array id="swa" count="1">1</float_array>'
        '<technique_common><accessor source="#swa" count="1" stride="1"><param name="WEIGHT" type="float"/>'
        '</accessor></technique_common></source><joints><input semantic="JOINT" source="#jn"/>'
        '<input semantic="INV_BIND_MATRIX" source="#ib"/></joints><vertex_weights count="8">'
        '<input semantic="JOINT" source="#jn" offset="0"/><input semantic="WEIGHT" source="#sw" offset="1"/>'
        '<vcount>1 1 1 1 1 1 1 1</vcount><v>0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0</v></vertex_weights></skin>'
        '</controller></library_controllers>')
    assert text.count('<instance_geometry url="#g">') == 1
    return (text.replace("<library_visual_scenes>", controller + "<library_visual_scenes>")
            .replace('<instance_geometry url="#g">', '<instance_controller url="#c">')
            .replace("</instance_geometry>", "</instance_controller>")
            .replace('<visual_scene id="s">', '<visual_scene id="s"><node id="bone" sid="bone" type="JOINT"/>'))


def test_a_skinned_mesh_is_seen_where_webots_draws_it(tmp_path: Path) -> None:
    """A rigged model's mesh (<instance_controller> of a skin) is read, not lost: Webots draws assimp's
    mesh without its bone weights, its geometry's vertices placed by the node that holds it (the
    node's 2 m translation counts, the skin's bind shape matrix, here 10 m, does not), in its material's
    colour."""
    text = dae(CORNERS - [0.5, 0.5, 0.0], [("m", CUBE)], materials={"m": ("paint", (0.5, 0.25, 1.0))},
               matrix=[[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    (tmp_path / "rig.dae").write_text(skinned(text, [[1, 0, 0, 10], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "rig.dae" ] } ] }\n'
                      'Robot { name "r" children [ DistanceSensor { name "ir" translation 2.2 0.1 2 '
                      'rotation 0 1 0 1.5707963267948966 type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ] } ] }\n')
    w = load_world(p)
    assert [(s.geometry.material_index, s.appearance.base_color) for s in w.world.solids[0].shapes] == [
        (0, (0.5, 0.25, 1.0))]
    assert read_all(Simulation(w, precision="exact"))["ir"] == pytest.approx(expected(1.0, 0.5), rel=1e-9)


def test_an_mtl_library_whose_name_has_spaces_is_read(tmp_path: Path) -> None:
    """``mtllib My Robot.mtl`` (Blender writes the file's name as it is): assimp reads the rest of the
    line as one file, and so is it read here (so ``mtllib a.mtl b.mtl`` names no file there, and its
    faces stay one white mesh, as in Webots)."""
    (tmp_path / "My Robot.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "a.mtl").write_text("newmtl blue\nKd 0 0 1\n")
    (tmp_path / "b.mtl").write_text("newmtl green\nKd 0 1 0\n")
    quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    (tmp_path / "one.obj").write_text(f"mtllib My Robot.mtl\n{quad}usemtl red\nf 1 2 3\nf 1 3 4\n")
    (tmp_path / "two.obj").write_text(f"mtllib a.mtl b.mtl\n{quad}usemtl blue\nf 1 2 3\nusemtl green\nf 1 3 4\n")
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "one.obj" ] } CadShape { url [ "two.obj" ] } ] }\n')
    assert [(s.geometry.url, s.geometry.material_index, s.appearance.base_color if s.appearance else None)
            for s in load_world(p).world.solids[0].shapes] == [("one.obj", 0, (1.0, 0.0, 0.0)), ("two.obj", -1, None)]


def test_a_concave_polygon_is_cut_into_ears_not_fanned(tmp_path: Path) -> None:
    """A <polylist> face shaped as an L (CAD exporters write such n-gons): assimp's Triangulate cuts a
    concave polygon into ears, so nothing is seen where the L has no material, though a fan from its
    first corner would cover it; inside, the texel at the corner's texture coordinates is read."""
    (tmp_path / "img").mkdir()
    save_board(tmp_path / "img" / "board.png")
    corners = [(2, 1), (1, 1), (1, 2), (0, 2), (0, 0), (2, 0)]     # a fan from the first or last corner leaves the L
    positions = " ".join(f"{x} {y} 0" for x, y in corners)
    uvs = " ".join(f"{x / 2} {y / 2}" for x, y in corners)
    text = dae([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [("m", [(0, 1, 2)])], uv=[[0, 0], [1, 0], [0, 1]],
               materials={"m": ("board", "img/board.png")})
    text = text.replace('count="9">0 0 0 1 0 0 0 1 0</float_array>', f'count="18">{positions}</float_array>') \
        .replace('accessor source="#pa" count="3"', 'accessor source="#pa" count="6"') \
        .replace('count="6">0 0 1 0 0 1</float_array>', f'count="12">{uvs}</float_array>') \
        .replace('accessor source="#ta" count="3"', 'accessor source="#ta" count="6"') \
        .replace('<triangles material="m" count="1">', '<polylist material="m" count="1"><vcount>6</vcount>') \
        .replace("<p>0 0 1 1 2 2</p></triangles>", "<p>0 0 1 1 2 2 3 3 4 4 5 5</p></polylist>")
    assert "polylist" in text and 'count="18"' in text and 'count="12"' in text
    (tmp_path / "L.dae").write_text(text)
    down = 'rotation 0 1 0 1.5707963267948966 type "infra-red" lookupTable [ 0 0 0, 10 10000 0 ]'
    p = wbt(tmp_path, 'Solid { children [ CadShape { url [ "L.dae" ] } ] }\n'
                      f'Robot {{ name "r" children [ DistanceSensor {{ name "in" translation 0.5 1.5 0.0625 {down} }}\n'
                      f'  DistanceSensor {{ name "out" translation 1.3 1.5 0.0625 {down} }} ] }}\n')
    v = read_all(Simulation(load_world(p), precision="exact"))
    # (x, y) = (0.5, 1.5) → (s, t) = (0.25, 0.75) → column 1, row 1
    assert v["in"] == pytest.approx(expected(0.0625, REDS[1, 1] / 255), rel=1e-9)
    assert v["out"] == pytest.approx(10000.0)


@pytest.mark.parametrize("reverse", [False, True])
def test_a_comb_shaped_face_is_cut_into_ears_that_cover_it_exactly(reverse: bool) -> None:
    """A comb of 16 teeth (corners on the diagonals' lines, the case a naive ear test gets wrong): its
    n − 2 ears cover exactly its area, 2·16 − 0.5 + 9·16 m², in the face's own winding."""
    from sensorium.server.world.cad import ear_clip

    top = [c for i in range(16) for c in [(2 * i, 1), (2 * i, 10), (2 * i + 1, 10), (2 * i + 1, 1)]]
    points = np.array([(x, y, 0.0) for x, y in [(0, 0), (32, 0), *top[::-1]]])
    if reverse:
        points = points[::-1].copy()
    ears = ear_clip(points)
    assert ears is not None and len(ears) == len(points) - 2
    a = points[ears]
    turns = np.cross(a[:, 1] - a[:, 0], a[:, 2] - a[:, 0])[:, 2]
    assert np.abs(turns).sum() / 2 == pytest.approx(11 * 16 - 0.5, abs=1e-9)
    assert ((turns < 0) if reverse else (turns > 0)).all()
