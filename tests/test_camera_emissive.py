"""Emissive colours in camera images, as Webots' shaders add them: WREN's phong.frag writes
``emissive + ambient + diffuse (+ specular)`` and pbr.frag adds the emissive colour to the lit one,
so a surface of albedo d, emissive colour e (a PBRAppearance's ``emissiveIntensity`` 1 here; where WREN's
forward shader multiplies by it: tests/test_camera_emissive_intensity.py)
sends ``d·Σ lights + e`` into the HDR buffer, and glows with ``e`` alone where no light reaches.

Closed forms: a camera at the origin looking along +x at a flat wall (face x = 1.95) lit by an
ambient-only directional light (0.3) and a point light at the camera (0.8, so ``0.8·cos`` of the
pixel's ray): each pixel reads Webots' resolve of ``d·(0.3 + 0.8·cos) + e``; in a world with no
light an emissive box reads the resolve of ``e`` and a plain one black. The batched camera gives
every copy the single simulation's bytes. A world where nothing glows adds nothing (no array)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests.test_batched_camera import images_with_robot_placed
from tests.test_camera_light_radius import AMBIENT, BOTH, CAM, byte, point, rays, shoot

DIFFUSE, GLOW = [0.6, 0.3, 0.15], [0.05, 0.4, 0.7]


def wall(appearance: dict) -> dict:
    return {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
            "appearance": appearance}


def world(lights, appearance: dict, robot_extra: dict | None = None) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [wall(appearance)], "lights": list(lights),
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **CAM}], **(robot_extra or {})}]})


def wbt_image(path: Path) -> np.ndarray:
    """The (H, W, 3) red, green, blue bytes of the first image of the camera ``robot/cam`` in world file ``path``."""
    sim = Simulation(load_world(path))
    cam = sim.device("robot/cam")
    cam.enable(16)
    sim.run(1)
    return cam.image[:, :, [2, 1, 0]].astype(np.int64)


@pytest.mark.parametrize("precision", BOTH)
def test_a_lit_face_reads_its_lit_colour_plus_its_emissive_colour(precision: str):
    _, cos = rays()
    lit = np.asarray(DIFFUSE) * (0.3 + 0.8 * cos)[..., None]
    plain = shoot(world([AMBIENT, point(None)], {"base_color": DIFFUSE}), precision)
    np.testing.assert_array_equal(plain, byte(lit))
    got = shoot(world([AMBIENT, point(None)], {"base_color": DIFFUSE, "emissive_color": GLOW}), precision)
    np.testing.assert_array_equal(got, byte(lit + np.asarray(GLOW)))
    assert (got > plain).all()


@pytest.mark.parametrize("precision", BOTH)
def test_an_emissive_box_glows_in_a_world_without_light(precision: str):
    got = shoot(world([], {"base_color": DIFFUSE, "emissive_color": GLOW}), precision)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(np.asarray(GLOW)), got.shape))
    dark = shoot(world([], {"base_color": DIFFUSE}), precision)
    assert not dark.any()


def test_nothing_is_added_where_nothing_glows():
    sim = Simulation(world([AMBIENT], {"base_color": DIFFUSE}))
    assert sim.scene.emissive is None
    sim = Simulation(world([AMBIENT], {"base_color": DIFFUSE, "emissive_color": GLOW}))
    assert sim.scene.emissive is not None and sim.scene.emissive[0].tolist() == GLOW
    assert sim.scene.emissive[-1].tolist() == [0.0, 0.0, 0.0]           # no hit: the sky adds nothing


WBT = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
DirectionalLight {{ direction 1 0 0 intensity 0 ambientIntensity 0.3 }}
Solid {{
  translation 2 0 0
  children [ Shape {{ appearance {appearance} geometry Box {{ size 0.1 20 20 }} }} ]
}}
Robot {{ children [ Camera {{ name "cam" width 9 height 7 fieldOfView 1 }} ] controller "<none>" }}
"""


@pytest.mark.parametrize("appearance, glow", [
    ("Appearance { material Material { diffuseColor 0.6 0.3 0.15 emissiveColor 0.05 0.4 0.7 } }", GLOW),
    ("PBRAppearance { baseColor 0.6 0.3 0.15 metalness 0 emissiveColor 0.05 0.4 0.7 }", GLOW),
])
def test_a_world_files_emissive_colours_are_drawn(tmp_path: Path, appearance: str, glow):
    """A Material's emissiveColor; a PBRAppearance's (its emissiveIntensity: test_camera_emissive_intensity.py)."""
    path = tmp_path / "glow.wbt"
    path.write_text(WBT.format(appearance=appearance))
    got = wbt_image(path)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(0.3 * np.asarray(DIFFUSE) + np.asarray(glow)), got.shape))


def _facing(glass: bool) -> LoadedWorld:
    """A bodiless robot whose camera faces a wall that glows and a box that does not (or, ``glass``,
    a semi-transparent one that glows too), under the ambient light and a point light it carries."""
    dev = {"device": "Camera", "name": "cam", "width": 11, "height": 5, "field_of_view": 1.0}
    box = {"name": "box", "pose": {"translation": [1.5, 0.4, 0.0]}, "geometry": {"type": "box", "size": [0.2, 0.2, 0.2]},
           "appearance": {"base_color": [0.9, 0.9, 0.2]}}
    if glass:
        box["appearance"] = {"base_color": [0.9, 0.9, 0.2], "transparency": 0.5, "emissive_color": [0.3, 0.0, 0.1]}
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False}, "lights": [AMBIENT],
        "solids": [wall({"base_color": DIFFUSE, "emissive_color": GLOW}), box],
        "robots": [{"name": "bot", "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2,
                                                          "max_wheel_speed": 10.0},
                    "lights": [point(None, intensity=0.6)], "devices": [dev]}]})
    return LoadedWorld(world=w, source="<test>", base_dir=Path.cwd())


@pytest.mark.parametrize("glass", [False, True])
@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_draws_emissive_colours_as_the_single_simulation(precision: str, glass: bool):
    x = [1.4, 0.9, -1.0]
    img = images_with_robot_placed(_facing(glass), precision, "bot", [[xc, 0.0, 0.0] for xc in x])
    centre = img[:, 2, 5, 2::-1].astype(np.int64)          # its ray along +x meets the wall face on
    for c in range(len(x)):
        L = np.asarray(DIFFUSE) * (0.3 + 0.6) + np.asarray(GLOW)
        np.testing.assert_array_equal(centre[c], byte(L), err_msg=str(c))


# ---------------------------------------------------------------------------------- a Charger's glow

def _charger_world(gradual: bool, initial=(0.0, 0.0, 0.2)) -> wm.World:
    """A camera in the dark facing a Charger's box (its own emissive colour ``initial``): the Charger
    starts empty and gathers 10 W up to 1 J, full after 100 ms; a second shape of its solid does not
    glow (glow_shapes 1)."""
    dock = {"name": "dock", "pose": {"translation": [2.0, 0.0, 0.0]},
            "shapes": [{"geometry": {"type": "box", "size": [0.1, 20, 20]},
                        "appearance": {"base_color": [0.5, 0.5, 0.5], "emissive_color": list(initial)}},
                       {"pose": {"translation": [0.0, 0.0, 30.0]}, "geometry": {"type": "box", "size": [0.1, 1, 1]},
                        "appearance": {"emissive_color": [0.1, 0.1, 0.1]}}]}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16}, "solids": [dock],
        "chargers": [{"solid": "dock", "battery": [0.0, 1.0, 10.0], "emissive_color": [1.0, 0.5, 0.0],
                      "gradual": gradual}],
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **CAM}]}]})


@pytest.mark.parametrize("gradual", [True, False])
def test_a_chargers_first_shape_glows_with_its_energy(gradual: bool):
    """Webots' WbCharger: full, the emissiveColor; else, gradual, initial + (emissiveColor − initial)·E/Emax;
    not gradual, the shape's own colour. The image after each step reads the energy of that step."""
    sim = Simulation(_charger_world(gradual))
    cam = sim.device("r/cam")
    cam.enable(16)
    initial, full = np.array([0.0, 0.0, 0.2]), np.array([1.0, 0.5, 0.0])
    seen = set()
    for step in range(1, 10):
        sim.run(1)
        energy = min(10.0 * 0.016 * step, 1.0)
        assert sim.chargers[0].energy == pytest.approx(energy, abs=1e-12)
        e = full if energy >= 1.0 else (initial + (full - initial) * energy if gradual else initial)
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        np.testing.assert_array_equal(got, np.broadcast_to(byte(e), got.shape), err_msg=str(step))
        seen.add(got.tobytes())
    assert len(seen) == (7 if gradual else 2)          # 0.16 J a step: full from the 7th
    assert sim.scene.emissive[1].tolist() == [0.1, 0.1, 0.1]       # the second shape keeps its own
    sim.reset()                                      # the loaded energy (0 J): the initial colour again
    sim.run(1)
    e = initial + (full - initial) * 0.16 if gradual else initial
    np.testing.assert_array_equal(cam.image[2, 4, 2::-1].astype(np.int64), byte(e))


CHARGER_WBT = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
Charger {{
  translation 2 0 0
  children [
    Pose {{ children [ Shape {{ appearance PBRAppearance {{ baseColor 0.5 0.5 0.5 emissiveColor 0 0 0.2 }}
                               geometry Box {{ size 0.1 20 20 }} }} ] }}
    Shape {{ appearance Appearance {{ material Material {{ emissiveColor 0.1 0.1 0.1 }} }} geometry Box {{ size 0.1 1 1 }} }}
  ]
  name "dock"
  battery [ 0, 1, 10 ]
  emissiveColor 1 0.5 0
  gradual {gradual}
}}
Robot {{ children [ Camera {{ name "cam" width 9 height 7 fieldOfView 1 }} ] controller "<none>" }}
"""


@pytest.mark.parametrize("gradual", ["TRUE", "FALSE"])
def test_a_wbt_chargers_first_child_glows(tmp_path: Path, gradual: str):
    path = tmp_path / "dock.wbt"
    path.write_text(CHARGER_WBT.format(gradual=gradual))
    lw = load_world(path)
    charger = lw.world.chargers[0]
    assert (charger.glow_shapes, charger.gradual, charger.emissive_color) == (1, gradual == "TRUE", (1.0, 0.5, 0.0))
    sim = Simulation(lw)
    cam = sim.device("robot/cam")
    cam.enable(16)
    sim.run(3)
    e = np.array([0.0, 0.0, 0.2]) + (np.array([1.0, 0.5, 0.0]) - [0.0, 0.0, 0.2]) * 0.48 if gradual == "TRUE" \
        else np.array([0.0, 0.0, 0.2])
    np.testing.assert_array_equal(cam.image[3, 4, 2::-1].astype(np.int64), byte(e))
    assert sim.scene.emissive[1].tolist() == [0.1, 0.1, 0.1]


def test_the_batched_simulation_refuses_a_glow_a_camera_sees_in_one_line():
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation
    lw = LoadedWorld(world=_charger_world(True), source="<dock>", base_dir=Path.cwd())
    with pytest.raises(BatchedError, match=r"^<dock>: Charger 'dock': its shapes glow with its energy, which camera "
                                           r"r/cam sees; .*glow_shapes: 0 and glow_solids: 0\)$"):
        BatchedSimulation(lw, 2)
    w = lw.world
    calm = w.model_copy(update={"chargers": [w.chargers[0].model_copy(update={"glow_shapes": 0})]})
    BatchedSimulation(LoadedWorld(world=calm, source="<dock>", base_dir=Path.cwd()), 2)      # accepted


# ------------------------------------------------------------------- a texture's colour on the glow

TEXEL = (200, 100, 50)


def _linear(byte_value: int) -> float:
    """The sRGB decoding WREN's shaders apply to a texel (SRGBtoLINEAR)."""
    c = byte_value / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


@pytest.fixture
def texel_dir(tmp_path: Path) -> Path:
    from PIL import Image
    Image.fromarray(np.full((2, 2, 3), TEXEL, dtype=np.uint8), "RGB").save(tmp_path / "t.png")
    return tmp_path


@pytest.mark.parametrize("phong", [True, False])
@pytest.mark.parametrize("precision", BOTH)
def test_a_phong_surfaces_glow_is_multiplied_by_its_texel(texel_dir: Path, precision: str, phong: bool):
    """WREN's phong.frag writes ``texel·(emissive + ambient + diffuse)``: a flat-lit textured face of
    texel t, colour d, emissive e reads ``d·t·(0.3 + 0.8·cos) + e·t``; its PBR shader adds e as it is."""
    _, cos = rays()
    t = np.array([_linear(v) for v in TEXEL])
    appearance = {"base_color": DIFFUSE, "texture": "t.png", "emissive_color": GLOW, "phong": phong}
    sim = Simulation(world([AMBIENT, point(None)], appearance), precision=precision, base_dir=texel_dir)
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
    glow = np.asarray(GLOW) * t if phong else np.asarray(GLOW)
    np.testing.assert_array_equal(got, byte(np.asarray(DIFFUSE) * t * (0.3 + 0.8 * cos)[..., None] + glow))
    assert (sim.scene.emissive_texel is not None) == phong
    calm = Simulation(world([AMBIENT], {**appearance, "emissive_color": [0.0, 0.0, 0.0]}), base_dir=texel_dir)
    assert calm.scene.emissive is None and calm.scene.emissive_texel is None     # nothing glows: nothing computed


@pytest.mark.parametrize("precision", BOTH)
def test_ink_on_a_phong_surface_mixes_into_its_glow(texel_dir: Path, precision: str):
    """WREN's Phong shader mixes the pen's ink into the texture colour before multiplying: in the dark
    a glowing textured box top reads ``e·((1 − c)·t + c·ink)``: ``e·t`` where no ink is, black under a
    stroke of black ink of density 1 (the pen test's stroke: a disc around the image's middle; the paint
    texture takes the image's size, so a 128-texel image keeps the disc as fine as there)."""
    import math

    from PIL import Image

    from tests.test_pen import pen
    Image.fromarray(np.full((128, 128, 3), TEXEL, dtype=np.uint8), "RGB").save(texel_dir / "fine.png")
    box = {"name": "box", "pose": {"translation": [0.0, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.4, 0.4, 0.2]},
           "appearance": {"texture": "fine.png", "emissive_color": GLOW, "phong": True}}
    down = [-1.0, 1.0, 1.0, 2.0 * math.pi / 3.0]     # +x to world -z
    cam = {"device": "Camera", "name": "cam", "width": 33, "height": 33, "field_of_view": 0.5,
           "pose": {"translation": [0.0, 0.0, 1.0], "rotation": down}}
    w = wm.World.model_validate({"world_info": {"contact": False}, "solids": [box], "robots": [
        {"name": "r", "devices": [pen(z=0.5, ink_density=1.0, lead_size=0.03), cam]}]})
    sim = Simulation(w, precision=precision, base_dir=texel_dir)
    sim.device("r/cam").enable(16)
    sim.step()
    assert sim.scene.textures.ink[0].density.max() == 1.0
    img = sim.device("r/cam").image[:, :, [2, 1, 0]].astype(np.int64)
    t = np.array([_linear(v) for v in TEXEL])
    assert img[16, 16].tolist() == [0, 0, 0]
    np.testing.assert_array_equal(img[2, 2], byte(np.asarray(GLOW) * t))


@pytest.mark.parametrize("appearance, textured_glow", [
    ('Appearance { material Material { emissiveColor 0.05 0.4 0.7 } texture ImageTexture { url "t.png" } }', True),
    ('PBRAppearance { metalness 0 emissiveColor 0.05 0.4 0.7 baseColorMap ImageTexture { url "t.png" } }', False),
])
def test_a_world_files_textured_appearance_multiplies_its_glow(texel_dir: Path, appearance: str, textured_glow: bool):
    """An Appearance's texture replaces its diffuse colour by white and multiplies its emissive colour
    (Phong); a PBRAppearance's baseColorMap does not touch its emissive colour."""
    path = texel_dir / "glow.wbt"
    path.write_text(WBT.format(appearance=appearance))
    got = wbt_image(path)
    t = np.array([_linear(v) for v in TEXEL])
    glow = np.asarray(GLOW) * (t if textured_glow else 1.0)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(0.3 * t + glow), got.shape))


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_multiplies_a_phong_glow_by_its_texel_as_the_single_simulation(texel_dir: Path, precision: str):
    lw = _facing(False)
    w = lw.world
    textured = w.solids[0].model_copy(update={"appearance": wm.Appearance.model_validate(
        {"base_color": DIFFUSE, "texture": "t.png", "emissive_color": GLOW, "phong": True})})
    lw = LoadedWorld(world=w.model_copy(update={"solids": [textured, *w.solids[1:]]}), source="<test>",
                     base_dir=texel_dir)
    x = [1.4, 0.9, -1.0]
    img = images_with_robot_placed(lw, precision, "bot", [[xc, 0.0, 0.0] for xc in x])
    t = np.array([_linear(v) for v in TEXEL])
    centre = img[:, 2, 5, 2::-1].astype(np.int64)
    for c in range(len(x)):
        np.testing.assert_array_equal(centre[c], byte(np.asarray(DIFFUSE) * t * (0.3 + 0.6) + np.asarray(GLOW) * t),
                                      err_msg=str(c))


# ------------------------------------------------------------------------------ an emissive map

MAP_TEXEL = (30, 180, 90)


@pytest.fixture
def map_dir(texel_dir: Path) -> Path:
    from PIL import Image
    Image.fromarray(np.full((2, 2, 3), MAP_TEXEL, dtype=np.uint8), "RGB").save(texel_dir / "m.png")
    return texel_dir


@pytest.mark.parametrize("colour", [[0.0, 0.0, 0.0], GLOW])
@pytest.mark.parametrize("precision", BOTH)
def test_an_emissive_mapped_box_in_the_dark_reads_its_map(map_dir: Path, precision: str, colour):
    """WREN's PBR shaders take the emissiveColorMap's texel, as stored, for the emissive colour (it
    replaces emissiveColor): in the dark the box reads the resolve of ``texel / 255``, whatever its
    own colour, with or without a base texture (``t.png`` does not touch the glow)."""
    want = byte(np.asarray(MAP_TEXEL) / 255.0)
    for extra in ({}, {"texture": "t.png"}):
        appearance = {"base_color": DIFFUSE, "emissive_color": colour, "emissive_map": "m.png", **extra}
        sim = Simulation(world([], appearance), precision=precision, base_dir=map_dir)
        cam = sim.device("r/cam")
        cam.enable(16)
        sim.run(1)
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        np.testing.assert_array_equal(got, np.broadcast_to(want, got.shape), err_msg=str(extra))


def test_a_world_files_emissive_color_map_is_drawn(map_dir: Path):
    path = map_dir / "glow.wbt"
    path.write_text(WBT.format(appearance='PBRAppearance { baseColor 0.6 0.3 0.15 metalness 0 emissiveColor 0.05 0.4 '
                                          '0.7 emissiveColorMap ImageTexture { url "m.png" } }'))
    lw = load_world(path)
    assert lw.world.solids[0].shapes[0].appearance.emissive_map.url == "m.png"      # type: ignore[union-attr]
    sim = Simulation(lw)
    cam = sim.device("robot/cam")
    cam.enable(16)
    sim.run(1)
    got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
    want = byte(0.3 * np.asarray(DIFFUSE) + np.asarray(MAP_TEXEL) / 255.0)
    np.testing.assert_array_equal(got, np.broadcast_to(want, got.shape))


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_reads_an_emissive_map_as_the_single_simulation(map_dir: Path, precision: str):
    lw = _facing(False)
    w = lw.world
    mapped = w.solids[0].model_copy(update={"appearance": wm.Appearance.model_validate(
        {"base_color": DIFFUSE, "emissive_map": "m.png"})})
    lw = LoadedWorld(world=w.model_copy(update={"solids": [mapped, *w.solids[1:]]}), source="<test>",
                     base_dir=map_dir)
    x = [1.4, 0.9, -1.0]
    img = images_with_robot_placed(lw, precision, "bot", [[xc, 0.0, 0.0] for xc in x])
    centre = img[:, 2, 5, 2::-1].astype(np.int64)
    for c in range(len(x)):
        np.testing.assert_array_equal(centre[c], byte(np.asarray(DIFFUSE) * (0.3 + 0.6) + np.asarray(MAP_TEXEL) / 255),
                                      err_msg=str(c))


# ------------------------------------------------------------- a Charger's lights and nested solids

LIGHT0, FULL = np.array([0.2, 0.4, 1.0]), np.array([1.0, 0.5, 0.0])


def _lamp_world(nested_glow: bool) -> wm.World:
    """A camera facing a wall lit only by the ambient term (0.3) of a light the Charger's solid holds
    (colour LIGHT0); ``nested_glow``: the wall is a solid nested in the Charger's (glow_solids: 1), its
    emissive colour (0, 0, 0.2) following the energy too, else a solid of its own and only the light
    follows (glow_lights: 1). The Charger starts empty and gathers 0.16 J a step up to 1 J."""
    lamp = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.3,
            "color": LIGHT0.tolist()}
    glowing_wall = {**wall({"base_color": DIFFUSE, "emissive_color": [0.0, 0.0, 0.2]}), "name": "inner"}
    dock = {"name": "dock", "pose": {"translation": [-5.0, 0.0, 0.0]}, "lights": [lamp]}
    if nested_glow:
        dock["children"] = [{**glowing_wall, "pose": {"translation": [7.0, 0.0, 0.0]}}]
        solids = [dock]
        charger = {"glow_shapes": 0, "glow_solids": 1}
    else:
        solids = [dock, wall({"base_color": DIFFUSE})]
        charger = {"glow_shapes": 0, "glow_lights": 1}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16}, "solids": solids,
        "chargers": [{"solid": "dock", "battery": [0.0, 1.0, 10.0], "emissive_color": FULL.tolist(), **charger}],
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **CAM}]}]})


@pytest.mark.parametrize("nested_glow", [False, True])
def test_a_chargers_light_and_nested_solid_follow_its_energy(nested_glow: bool):
    """WbCharger::updateMaterialsAndLights: a light's colour takes the rule of the emissive colour,
    c0 + (emissiveColor − c0)·E/Emax (full: emissiveColor); a solid inside its first child is searched as
    a group, so its shapes glow so too. The wall reads ``0.3·light·d (+ glow)`` after each step."""
    sim = Simulation(_lamp_world(nested_glow))
    cam = sim.device("r/cam")
    cam.enable(16)
    own = np.array([0.0, 0.0, 0.2])
    seen = set()
    for step in range(1, 9):
        sim.run(1)
        energy = min(0.16 * step, 1.0)
        light = FULL if energy >= 1.0 else LIGHT0 + (FULL - LIGHT0) * energy
        L = 0.3 * light * np.asarray(DIFFUSE)
        if nested_glow:          # the light is not in its first child: its own colour
            L = 0.3 * LIGHT0 * np.asarray(DIFFUSE) + (FULL if energy >= 1.0 else own + (FULL - own) * energy)
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        np.testing.assert_array_equal(got, np.broadcast_to(byte(L), got.shape), err_msg=str(step))
        seen.add(got.tobytes())
    assert len(seen) == 7                # full from the 7th step
    sim.reset()                          # the loaded energy (0 J): the light's own colour again
    sim.run(1)
    light = LIGHT0 if nested_glow else LIGHT0 + (FULL - LIGHT0) * 0.16
    glow = own + (FULL - own) * 0.16 if nested_glow else 0.0
    np.testing.assert_array_equal(cam.image[3, 4, 2::-1].astype(np.int64), byte(0.3 * light * np.asarray(DIFFUSE) + glow))


LAMP_WBT = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
Charger {{
  translation -5 0 0
  children [
    Group {{ children [
      DirectionalLight {{ direction 1 0 0 intensity 0 ambientIntensity 0.3 color 0.2 0.4 1 }}
      Solid {{ translation 7 0 0 name "inner"
               children [ Shape {{ appearance PBRAppearance {{ baseColor 0.6 0.3 0.15 metalness 0
                                                               emissiveColor 0 0 0.2 }}
                                   geometry Box {{ size 0.1 20 20 }} }} ] }}
    ] }}
    DirectionalLight {{ direction 1 0 0 intensity 0 ambientIntensity 0.1 }}
  ]
  name "dock"
  battery [ 0, 1, 10 ]
  emissiveColor 1 0.5 0
}}
Robot {{ children [ Camera {{ name "cam" width 9 height 7 fieldOfView 1 }} ] controller "<none>" }}
"""


def test_a_wbt_chargers_first_child_lights_and_solids_follow_its_energy(tmp_path: Path):
    """The first child (a Group) holds a light and a Solid: both follow the energy; the second light
    keeps its white colour."""
    path = tmp_path / "lamp.wbt"
    path.write_text(LAMP_WBT.format())
    lw = load_world(path)
    charger = lw.world.chargers[0]
    assert (charger.glow_shapes, charger.glow_lights, charger.glow_solids) == (0, 1, 1)
    sim = Simulation(lw)
    cam = sim.device("robot/cam")
    cam.enable(16)
    sim.run(3)
    own = np.array([0.0, 0.0, 0.2])
    L = (0.3 * (LIGHT0 + (FULL - LIGHT0) * 0.48) + 0.1) * np.asarray(DIFFUSE) + own + (FULL - own) * 0.48
    np.testing.assert_array_equal(cam.image[3, 4, 2::-1].astype(np.int64), byte(L))


def test_the_batched_simulation_refuses_a_chargers_light_a_sensor_sees_in_one_line():
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation
    lw = LoadedWorld(world=_lamp_world(False), source="<dock>", base_dir=Path.cwd())
    with pytest.raises(BatchedError, match=r"^<dock>: Charger 'dock': its lights' colour follows its energy, which "
                                           r"r/cam sees; .*glow_lights: 0 and glow_solids: 0\)$"):
        BatchedSimulation(lw, 2)
