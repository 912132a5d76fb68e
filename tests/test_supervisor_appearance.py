"""A Supervisor changing what shapes look like (tests/worlds/appearance_change.wbt): a solid's and a
robot's Shape nodes with their appearance, material and geometry, found by DEF and through
``children``; their fields read as the world file wrote them (Webots' defaults for the rest); a
colour, roughness or transparency set is what cameras and infra-red sensors see from the next step,
bit for bit as a world file saying it (closed form: an ambient-only light of 0.5 on a flat face, a
pixel is ``round(255 (1 - e^(-0.5 albedo))^(1/2.2))``). The same from Python and C controllers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller
from test_multiprocess import REPO

from sensorium.schemas import world as wm
from sensorium.server.daemon import export
from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon.nested import FIRST_ID
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "appearance_change.wbt"
AMBIENT = 0.5
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


def expected_bytes(albedo) -> list[int]:
    """Webots' HDR resolve of an ambient-lit face, RGB bytes."""
    L = AMBIENT * np.asarray(albedo, dtype=np.float64)
    return np.floor(255.0 * (1.0 - np.exp(-L)) ** (1.0 / 2.2) + 0.5).astype(np.int64).tolist()


def _sim(path=WORLD) -> Simulation:
    sim = Simulation(load_world(path))
    sim.device("looker/cam").enable(16)
    sim.device("looker/ir").enable(16)
    return sim


def _shot(sim: Simulation) -> tuple[np.ndarray, float]:
    sim.run(1)
    return sim.device("looker/cam").image.copy(), float(sim.device("looker/ir").value)


def _variant(tmp_path, old: str, new: str):
    text = WORLD.read_text()
    assert old in text
    path = tmp_path / "variant.wbt"
    path.write_text(text.replace(old, new))
    return path


def field(sim, node, name):
    return sv.get_field(sim, node, name)["value"]


def test_shapes_and_their_nodes_are_served_after_the_other_nested_nodes():
    sim = _sim()
    wall, panel, looker = (sv.find_node(sim, d) for d in ("WALL", "PANEL", "LOOKER"))
    shape = sv.find_node(sim, "WALL_SHAPE")
    assert field(sim, wall, "children") == [shape.id]
    assert (shape.type, sv.node_ref(sim, shape)["parent"]) == ("Shape", wall.id)
    app = sv.node_by_id(sim, field(sim, shape, "appearance"))
    assert (app.type, app.def_name) == ("PBRAppearance", "WALL_APP") and app == sv.find_node(sim, "WALL_APP")
    box = sv.node_by_id(sim, field(sim, shape, "geometry"))
    assert (box.type, box.def_name, field(sim, box, "size")) == ("Box", "WALL_BOX", [0.1, 20.0, 20.0])
    # written values, Webots' defaults for the others
    assert field(sim, app, "baseColor") == [0.8, 0.5, 0.2]
    assert (field(sim, app, "roughness"), field(sim, app, "metalness"), field(sim, app, "transparency")) == (0.3, 0.0, 0.0)
    assert (field(sim, app, "emissiveColor"), field(sim, app, "IBLStrength")) == ([0.0, 0.0, 0.0], 1.0)
    assert field(sim, shape, "castShadows") is True
    # a solid's children in file order: the nested solid LEG, then the Shape; the Material inside its Appearance
    leg, ball = field(sim, panel, "children")
    assert sv.node_by_id(sim, leg).def_name == "LEG"
    appearance = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, ball), "appearance"))
    assert appearance.type == "Appearance" and field(sim, appearance, "texture") == 0
    material = sv.node_by_id(sim, field(sim, appearance, "material"))
    assert material == sv.find_node(sim, "PANEL_MATERIAL") and material.type == "Material"
    assert field(sim, material, "diffuseColor") == [0.1, 0.9, 0.2] and field(sim, material, "transparency") == 0.25
    assert (field(sim, material, "shininess"), field(sim, material, "specularColor")) == (0.2, [0.0, 0.0, 0.0])
    sphere = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, ball), "geometry"))
    assert (sphere.type, field(sim, sphere, "radius")) == ("Sphere", 0.3)
    # a robot's shape between its devices, as the file writes it; an empty PBRAppearance: Webots' defaults
    cam, body, ir = (sv.node_by_id(sim, i) for i in field(sim, looker, "children"))
    assert (cam.type, body.def_name, ir.type) == ("Camera", "BODY", "DistanceSensor")
    body_app = sv.node_by_id(sim, field(sim, body, "appearance"))
    assert (field(sim, body_app, "baseColor"), field(sim, body_app, "metalness")) == ([1.0, 1.0, 1.0], 1.0)
    # appended after every other nested node: the earlier ids do not move
    assert (cam.id, ir.id, leg) == (FIRST_ID, FIRST_ID + 1, FIRST_ID + 2) and body.id > leg
    # Webots' node has no pose or children: NULL without a line
    assert sv.get_field(sim, shape, "translation").get("absent") and sv.get_field(sim, material, "children").get("absent")


def test_a_base_colour_set_is_seen_as_if_the_world_file_said_it(tmp_path):
    sim = _sim()
    img, ir = _shot(sim)
    assert img[2, 2, [2, 1, 0]].tolist() == expected_bytes([0.8, 0.5, 0.2])
    sv.set_field(sim, sv.find_node(sim, "WALL_APP"), "baseColor", [0.3, 0.6, 0.9])
    assert field(sim, sv.find_node(sim, "WALL_APP"), "baseColor") == [0.3, 0.6, 0.9]
    img2, ir2 = _shot(sim)
    assert np.all(img2[:, :, [2, 1, 0]] == expected_bytes([0.3, 0.6, 0.9]))
    ref_img, ref_ir = _shot(_sim(_variant(tmp_path, "baseColor 0.8 0.5 0.2", "baseColor 0.3 0.6 0.9")))
    assert np.array_equal(img2, ref_img) and ir2 == ref_ir and ir2 != ir      # infra-red reads the red 0.3


def test_roughness_and_a_materials_colour_and_transparency(tmp_path):
    sim = _sim()
    sv.set_field(sim, sv.find_node(sim, "WALL_APP"), "roughness", 0.9)
    img, ir = _shot(sim)
    ref = _shot(_sim(_variant(tmp_path, "roughness 0.3", "roughness 0.9")))
    assert np.array_equal(img, ref[0]) and ir == ref[1]
    assert ir != _shot(_sim())[1]                      # the infra-red reflection depends on roughness
    # the wall as an Appearance with a Material: its diffuseColor and transparency
    mat = "appearance DEF WALL_APP Appearance { material DEF WALL_MAT Material { diffuseColor 0.8 0.5 0.2 transparency 0.2 } }"
    pbr = "appearance DEF WALL_APP PBRAppearance {\n        baseColor 0.8 0.5 0.2\n        roughness 0.3\n        metalness 0\n      }"
    sim = _sim(_variant(tmp_path, pbr, mat))
    material = sv.find_node(sim, "WALL_MAT")
    sv.set_field(sim, material, "diffuseColor", [0.1, 0.2, 0.7])
    sv.set_field(sim, material, "transparency", 0.6)
    img, ir = _shot(sim)
    path = tmp_path / "ref.wbt"
    _variant(tmp_path, pbr, mat.replace("0.8 0.5 0.2 transparency 0.2", "0.1 0.2 0.7 transparency 0.6")).rename(path)
    ref = _shot(_sim(path))
    assert np.array_equal(img, ref[0]) and ir == ref[1]


def test_a_change_to_a_defd_node_reaches_the_shapes_that_use_it():
    sim = _sim()
    twin = sv.find_node(sim, "twin")
    used_app, used_material_shape = (sv.node_by_id(sim, i) for i in field(sim, twin, "children"))
    app = sv.node_by_id(sim, field(sim, used_app, "appearance"))
    material = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, field(sim, used_material_shape, "appearance")),
                                         "material"))
    assert (app.def_name, material.def_name) == ("", "")      # a USE is a node of its own, without the DEF
    assert field(sim, app, "baseColor") == [0.8, 0.5, 0.2] and field(sim, material, "diffuseColor") == [0.1, 0.9, 0.2]
    sv.set_field(sim, sv.find_node(sim, "WALL_APP"), "baseColor", [0.3, 0.6, 0.9])
    sv.set_field(sim, sv.find_node(sim, "PANEL_MATERIAL"), "diffuseColor", [0.5, 0.25, 0.125])
    assert field(sim, app, "baseColor") == [0.3, 0.6, 0.9] and field(sim, material, "diffuseColor") == [0.5, 0.25, 0.125]
    table = sv._table(sim)
    k_app, k_material = (table.get(n.id).shape.index for n in (app, material))
    assert sim.scene.colors[k_app].tolist() == [0.3, 0.6, 0.9] and sim.scene.colors[k_material].tolist() == [0.5, 0.25, 0.125]
    sv.set_field(sim, app, "roughness", 0.7)            # and from a USE to its DEF
    assert field(sim, sv.find_node(sim, "WALL_APP"), "roughness") == 0.7


def test_refusals_name_the_field_and_change_nothing():
    sim = _sim()
    app, box = sv.find_node(sim, "WALL_APP"), sv.find_node(sim, "WALL_BOX")
    before = _shot(sim)
    with pytest.raises(ValueError, match=r"'baseColor' .* must be in \[0, 1\]"):
        sv.set_field(sim, app, "baseColor", [0.1, 1.5, 0.2])
    with pytest.raises(ValueError, match=r"'transparency' .* must be in \[0, 1\], got 1.5"):
        sv.set_field(sim, app, "transparency", 1.5)
    with pytest.raises(ValueError, match="'size' .* read-only here: of a shape's nodes"):
        sv.set_field(sim, box, "size", [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="'IBLStrength' .* read-only"):
        sv.set_field(sim, app, "IBLStrength", 0.5)
    assert np.array_equal(_shot(sim)[0], before[0])
    # metalness is kept and read back (cameras here do not render it, as for the world file)
    sv.set_field(sim, app, "metalness", 0.7)
    assert field(sim, app, "metalness") == 0.7
    assert np.array_equal(_shot(sim)[0], before[0])


def test_an_emissive_colour_set_glows_as_if_the_world_file_said_it(tmp_path):
    """Every pixel of the ambient-lit wall reads 0.5·albedo + emissive (Webots' shaders add it); a
    PBRAppearance's emissiveIntensity (world file: 2) doubles it, as WREN's forward shader does where no
    light casts shadows (this world's)."""
    sim = _sim()
    app = sv.find_node(sim, "WALL_APP")
    sv.set_field(sim, app, "emissiveColor", [0.2, 0.0, 0.1])
    assert field(sim, app, "emissiveColor") == [0.2, 0.0, 0.1]
    img, _ = _shot(sim)
    L = AMBIENT * np.array([0.8, 0.5, 0.2]) + [0.2, 0.0, 0.1]
    assert img[2, 2, [2, 1, 0]].tolist() == np.floor(255.0 * (1.0 - np.exp(-L)) ** (1.0 / 2.2) + 0.5).astype(int).tolist()
    ref, _ = _shot(_sim(_variant(tmp_path, "roughness 0.3", "roughness 0.3 emissiveColor 0.2 0 0.1")))
    assert np.array_equal(img, ref)
    sim = _sim(_variant(tmp_path, "roughness 0.3", "roughness 0.3 emissiveIntensity 2"))
    sv.set_field(sim, sv.find_node(sim, "WALL_APP"), "emissiveColor", [0.2, 0.0, 0.1])
    L = AMBIENT * np.array([0.8, 0.5, 0.2]) + 2.0 * np.array([0.2, 0.0, 0.1])
    img, _ = _shot(sim)
    assert img[2, 2, [2, 1, 0]].tolist() == np.floor(255.0 * (1.0 - np.exp(-L)) ** (1.0 / 2.2) + 0.5).astype(int).tolist()
    sv.set_field(sim, sv.find_node(sim, "WALL_APP"), "emissiveColor", [0.0, 0.0, 0.0])     # back to no glow
    assert np.array_equal(_shot(sim)[0], _shot(_sim())[0]) and sim.scene.emissive is None


def test_an_emissive_intensity_set_scales_the_glow_as_if_the_world_file_said_it(tmp_path):
    """A PBRAppearance's emissiveIntensity a Supervisor sets multiplies its emissiveColor in the image
    (WREN's forward shader, this world's lights casting no shadows): the pixels of the world written
    with it, Webots' resolve of 0.5·albedo + 3·emissive; a negative or non-finite one is refused in one
    line, nothing changed; the reset brings the loaded 1 back."""
    sim = _sim()
    app = sv.find_node(sim, "WALL_APP")
    assert field(sim, app, "emissiveIntensity") == 1.0
    sv.set_field(sim, app, "emissiveColor", [0.2, 0.0, 0.1])
    sv.set_field(sim, app, "emissiveIntensity", 3.0)
    assert field(sim, app, "emissiveIntensity") == 3.0
    img, _ = _shot(sim)
    L = AMBIENT * np.array([0.8, 0.5, 0.2]) + 3.0 * np.array([0.2, 0.0, 0.1])
    assert img[2, 2, [2, 1, 0]].tolist() == np.floor(255.0 * (1.0 - np.exp(-L)) ** (1.0 / 2.2) + 0.5).astype(int).tolist()
    ref, _ = _shot(_sim(_variant(tmp_path, "roughness 0.3", "roughness 0.3 emissiveColor 0.2 0 0.1 emissiveIntensity 3")))
    assert np.array_equal(img, ref)
    with pytest.raises(ValueError, match=r"'emissiveIntensity' .* must be >= 0, got -0.5 .*nothing changed"):
        sv.set_field(sim, app, "emissiveIntensity", -0.5)
    for bad in (math.inf, math.nan):
        with pytest.raises(ValueError, match="'emissiveIntensity' is an SFFloat: takes a finite number"):
            sv.set_field(sim, app, "emissiveIntensity", bad)
    assert field(sim, app, "emissiveIntensity") == 3.0 and np.array_equal(_shot(sim)[0], img)
    assert "  emissiveIntensity 3\n" in export.node_string(sim, app)        # exportString writes it
    sv.set_field(sim, app, "emissiveIntensity", 0.0)           # no glow at all
    assert np.array_equal(_shot(sim)[0], _shot(_sim())[0])
    sim.reset()
    assert field(sim, app, "emissiveIntensity") == 1.0 and field(sim, app, "emissiveColor") == [0.0, 0.0, 0.0]


def test_a_simulation_reset_brings_the_loaded_colours_back():
    sim = _sim()
    first = _shot(sim)
    app = sv.find_node(sim, "WALL_APP")
    sv.set_field(sim, app, "baseColor", [0.0, 1.0, 0.0])
    assert not np.array_equal(_shot(sim)[0], first[0])
    sim.reset()
    assert field(sim, app, "baseColor") == [0.8, 0.5, 0.2]
    assert np.array_equal(_shot(sim)[0], first[0])


def _yaml_world(base_color) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "lights": [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": AMBIENT}],
        "solids": [{"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
                    "appearance": {"base_color": base_color}},
                   {"name": "post", "geometry": {"type": "box", "size": [1, 1, 1]}, "seen_by": "bounding"}],
        "robots": [{"name": "r", "supervisor": True, "devices": [{"device": "Camera", "name": "cam", "width": 3,
                                                                   "height": 3, "field_of_view": 0.5}]}]})


def test_a_yaml_shape_is_served_with_a_pbr_appearance_of_its_model():
    sim = Simulation(_yaml_world([0.8, 0.5, 0.2]))
    sim.device("r/cam").enable(16)
    wall, post = sv.find_node(sim, "wall"), sv.find_node(sim, "post")
    (shape,) = field(sim, wall, "children")
    assert field(sim, post, "children") == []             # a bounding-only shape is Webots' boundingObject
    app = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, shape), "appearance"))
    box = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, shape), "geometry"))
    assert (app.type, field(sim, app, "baseColor"), box.type, field(sim, box, "size")) == \
        ("PBRAppearance", [0.8, 0.5, 0.2], "Box", [0.1, 20.0, 20.0])
    sv.set_field(sim, app, "baseColor", [0.25, 0.5, 1.0])
    sim.run(1)
    ref = Simulation(_yaml_world([0.25, 0.5, 1.0]))
    ref.device("r/cam").enable(16)
    ref.run(1)
    assert np.array_equal(sim.device("r/cam").image, ref.device("r/cam").image)
    assert sim.device("r/cam").image[1, 1, [2, 1, 0]].tolist() == expected_bytes([0.25, 0.5, 1.0])


def test_a_yaml_texture_reads_its_model(tmp_path):
    from PIL import Image
    Image.new("RGB", (2, 2), (200, 100, 30)).save(tmp_path / "t.png")
    w = _yaml_world([1.0, 1.0, 1.0]).model_dump()
    w["solids"][0]["appearance"]["texture"] = {"url": "t.png", "repeat_s": False}
    sim = Simulation(wm.World.model_validate(w), base_dir=tmp_path)
    (shape,) = field(sim, sv.find_node(sim, "wall"), "children")
    app = sv.node_by_id(sim, field(sim, sv.node_by_id(sim, shape), "appearance"))
    texture = sv.node_by_id(sim, field(sim, app, "baseColorMap"))
    assert (texture.type, field(sim, texture, "url"), field(sim, texture, "repeatS"), field(sim, texture, "filtering")) \
        == ("ImageTexture", ["t.png"], False, 4)


def test_a_robots_own_shape_takes_its_new_colour():
    sim = _sim()
    body = sv.find_node(sim, "BODY")
    app = sv.node_by_id(sim, field(sim, body, "appearance"))
    k = sv._table(sim).get(body.id).shape.index
    assert sim.scene.colors[k].tolist() == [1.0, 1.0, 1.0]
    sv.set_field(sim, app, "baseColor", [0.5, 0.0, 0.25])
    assert sim.scene.colors[k].tolist() == [0.5, 0.0, 0.25] and sim.scene.red[k] == 0.5
    assert sim.scene.colors[:k].tolist() + sim.scene.colors[k + 1:].tolist() == \
        _sim().scene.colors[:k].tolist() + _sim().scene.colors[k + 1:].tolist()     # only its entries changed


PAINT = """#VRML_SIM R2023b utf8
PROTO Paint [
  field SFColor colorOverride 0.2 0.4 0.6
  field SFFloat gloss 0.5
]
{
  PBRAppearance {
    baseColor IS colorOverride
    roughness 0.5
  }
}
"""


def test_an_appearance_proto_is_named_by_its_proto_and_its_fields_pass_through(tmp_path):
    (tmp_path / "protos").mkdir()
    (tmp_path / "protos" / "Paint.proto").write_text(PAINT)
    text = WORLD.read_text()
    pbr = "appearance DEF WALL_APP PBRAppearance {\n        baseColor 0.8 0.5 0.2\n        roughness 0.3\n        metalness 0\n      }"
    text = text.replace("WorldInfo {", 'EXTERNPROTO "protos/Paint.proto"\nWorldInfo {', 1)
    (tmp_path / "paint.wbt").write_text(text.replace(pbr, "appearance DEF WALL_APP Paint { colorOverride 0.8 0.5 0.2 }"))
    sim = _sim(tmp_path / "paint.wbt")
    app = sv.find_node(sim, "WALL_APP")
    assert (app.proto, app.type) == ("Paint", "PBRAppearance")
    assert field(sim, app, "colorOverride") == [0.8, 0.5, 0.2] and field(sim, app, "gloss") == 0.5
    assert sv.get_field(sim, app, "baseColor").get("absent")                 # no interface field (Webots' NULL)
    assert sv.get_field(sim, app, "roughness", level=0)["value"] == 0.5      # getBaseNodeField
    sv.set_field(sim, app, "colorOverride", [0.3, 0.6, 0.9])                # IS baseColor: passes through
    assert _shot(sim)[0][2, 2, [2, 1, 0]].tolist() == expected_bytes([0.3, 0.6, 0.9])
    with pytest.raises(ValueError, match="'gloss' .* read-only here"):
        sv.set_field(sim, app, "gloss", 0.1)


# ---------------------------------------------------------------------- Python and C controllers
def _expected_lines() -> list[str]:
    before, after = expected_bytes([0.8, 0.5, 0.2]), expected_bytes([0.3, 0.6, 0.9])
    return [f"before {before[0]} {before[1]} {before[2]}",
            "nodes Shape PBRAppearance WALL_APP Box 1 1 1",
            "size 0.1 20 20",
            "color 0.8 0.5 0.2 0",
            f"after {after[0]} {after[1]} {after[2]} 0.3 0.6 0.9",
            "reached 1 1 Material",
            "material Material 0.1 0.9 0.2 0.25",
            "material 0.5 0.25 0.125"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "appearance_change.c")


def test_a_python_controller_sets_a_colour_its_camera_sees() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "appearance_change.py")), robot="looker")
    assert lines == _expected_lines(), err


def test_a_c_controller_does_the_same(c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV, robot="looker")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == _expected_lines(), err


# ------------------------------------------------------------------------ a Charger's glowing fields

CHARGER_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Charger {
  translation 2 0 0
  children [
    Group { children [
      Shape { appearance DEF GLOW_PBR PBRAppearance { baseColor 0.5 0.5 0.5 emissiveColor 0 0 0.2 } geometry Box { size 0.1 1 1 } }
      Shape { appearance Appearance { material DEF GLOW_MATERIAL Material { emissiveColor 0.2 0.4 0 } }
              geometry Box { size 0.1 1 1 } }
    ] }
    Shape { appearance Appearance { material DEF CALM_MATERIAL Material { emissiveColor 0.1 0.1 0.1 } }
            geometry Box { size 0.1 1 1 } }
  ]
  name "dock"
  battery [ 0, 1, 10 ]
  emissiveColor 1 0.5 0
}
Robot { controller "<none>" supervisor TRUE }
"""


def test_a_supervisor_reads_a_chargers_glowing_emissive_colour_now(tmp_path):
    """WbCharger writes its first child's materials' emissiveColor at each step: a Supervisor reads
    initial + (emissiveColor − initial)·E/Emax after n steps (10 W, 16 ms: E = 0.16·n J, full from the
    7th), a Material's and a PBRAppearance's, and exportString and worldSave write it so; its own write
    reads back until the next step, which writes the Charger's colour again; a shape outside the first
    child keeps its own."""
    path = tmp_path / "dock.wbt"
    path.write_text(CHARGER_WBT)
    sim = Simulation(load_world(path))
    glowing = {"GLOW_MATERIAL": np.array([0.2, 0.4, 0.0]), "GLOW_PBR": np.array([0.0, 0.0, 0.2])}
    nodes = {name: sv.find_node(sim, name) for name in glowing}
    full = np.array([1.0, 0.5, 0.0])

    def expect(energy: float, step: int) -> None:
        for name, initial in glowing.items():
            want = full if energy >= 1.0 else initial + (full - initial) * energy
            np.testing.assert_allclose(field(sim, nodes[name], "emissiveColor"), want, rtol=0, atol=1e-15,
                                       err_msg=f"{name} step {step}")

    for n in range(1, 9):
        sim.run(1)
        expect(min(0.16 * n, 1.0), n)
    assert field(sim, sv.find_node(sim, "CALM_MATERIAL"), "emissiveColor") == [0.1, 0.1, 0.1]
    # exportString and worldSave write the field as it is now (full: the Charger's colour), the calm one as written
    assert "  emissiveColor 1 0.5 0\n" in export.node_string(sim, nodes["GLOW_MATERIAL"])
    assert "  emissiveColor 1 0.5 0\n" in export.node_string(sim, nodes["GLOW_PBR"])
    saved = [line.strip() for line in export.world_string(sim).splitlines() if "emissiveColor" in line]
    assert saved == ["emissiveColor 1 0.5 0"] * 2 + ["emissiveColor 0.1 0.1 0.1", "emissiveColor 1 0.5 0"], saved
    sim.reset()
    expect(0.0, 0)                                  # the loaded energy, 0 J: the world file's colours
    sim.run(1)
    for node in nodes.values():
        sv.set_field(sim, node, "emissiveColor", [0.0, 0.0, 1.0])
        assert field(sim, node, "emissiveColor") == [0.0, 0.0, 1.0]   # the Supervisor's write, until...
    sim.run(1)                                                         # ...the Charger's next step
    expect(0.32, 2)
