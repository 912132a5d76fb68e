"""A PBRAppearance's emissiveIntensity in camera images, by WREN's rule: its forward shader (pbr.frag:
translucent shapes always, opaque ones while no light that is on casts shadows) multiplies the emissive
colour by it; its shadow-volume ambient-emissive shader (opaque shapes while a light that is on casts
shadows) leaves it out outside wireframe rendering.

Closed forms: a camera at the origin looking along +x at a wall (face x = 1.95) lit by an ambient-only
directional light (0.3) and a point light at the camera (0.8, so ``0.8·cos`` of the pixel's ray), which
casts shadows or not (nothing stands between it and the wall, so the lit term is the same): an opaque
wall of albedo d, emissive colour e and intensity I reads the resolve of ``d·(0.3 + 0.8·cos) + e·I``
without a shadow-casting light, ``… + e`` with one; a half-transparent wall (over the black sky) reads
``0.5·(d·(0.3 + 0.8·cos) + e·I)`` either way. An ``Appearance`` node (Phong) has no intensity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld
from tests.test_batched_camera import images_with_robot_placed, stepped_alike
from tests.test_camera_emissive import DIFFUSE, GLOW, MAP_TEXEL, wbt_image, world
from tests.test_camera_light_radius import AMBIENT, byte, point, rays

INTENSITY = 2.5


def _shot(sim: Simulation) -> np.ndarray:
    cam = sim.device("r/cam")
    if not cam.enabled:
        cam.enable(16)
    sim.run(1)
    return cam.image[:, :, [2, 1, 0]].astype(np.int64)


def _expected(transparency: float, intensity: float) -> np.ndarray:
    _, cos = rays()
    lit = np.asarray(DIFFUSE) * (0.3 + 0.8 * cos)[..., None]
    return byte((1.0 - transparency) * (lit + intensity * np.asarray(GLOW)))


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("transparency", [0.0, 0.5])
@pytest.mark.parametrize("casts", [False, True])
def test_the_intensity_applies_where_wrens_forward_shader_draws_the_shape(precision: str, transparency: float,
                                                                          casts: bool):
    app = {"base_color": DIFFUSE, "emissive_color": GLOW, "emissive_intensity": INTENSITY,
           "transparency": transparency}
    sim = Simulation(world([AMBIENT, point(None, cast_shadows=casts)], app), precision=precision)
    forward = transparency > 0.0 or not casts
    np.testing.assert_array_equal(_shot(sim), _expected(transparency, INTENSITY if forward else 1.0))


def test_a_phong_appearance_has_no_intensity():
    app = {"base_color": DIFFUSE, "emissive_color": GLOW, "emissive_intensity": INTENSITY, "phong": True}
    sim = Simulation(world([AMBIENT, point(None)], app))
    np.testing.assert_array_equal(_shot(sim), _expected(0.0, 1.0))
    assert sim.scene.emissive_intensity is None


def test_nothing_is_kept_where_nothing_glows_or_every_intensity_is_one():
    lights = [AMBIENT, point(None)]
    assert Simulation(world(lights, {"base_color": DIFFUSE, "emissive_intensity": 3.0})).scene.emissive_intensity is None
    assert Simulation(world(lights, {"base_color": DIFFUSE, "emissive_color": GLOW})).scene.emissive_intensity is None
    got = Simulation(world(lights, {"emissive_color": GLOW, "emissive_intensity": 3.0})).scene.emissive_intensity
    assert got is not None and got.tolist() == [3.0, 1.0]


def test_turning_the_shadow_casting_light_on_and_off_changes_the_glow_from_the_next_image():
    """A Supervisor's change of a top-level light (Scene.set_top_light, as its field setters call it):
    a shadow-casting lamp turned off leaves the ambient light alone, so ``0.3·d + e·I``; back on,
    ``d·(0.3 + 0.8·cos) + e``; its castShadows turned FALSE, ``… + e·I``."""
    lamp = wm.World.model_validate({"lights": [point(None, cast_shadows=True)]}).lights[0]
    app = {"base_color": DIFFUSE, "emissive_color": GLOW, "emissive_intensity": INTENSITY}
    sim = Simulation(world([AMBIENT, point(None, cast_shadows=True)], app))
    np.testing.assert_array_equal(_shot(sim), _expected(0.0, 1.0))
    sim.scene.set_top_light(1, lamp.model_copy(update={"on": False}))
    got = _shot(sim)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(0.3 * np.asarray(DIFFUSE) + INTENSITY * np.asarray(GLOW)),
                                                       got.shape))
    sim.scene.set_top_light(1, lamp)
    np.testing.assert_array_equal(_shot(sim), _expected(0.0, 1.0))
    sim.scene.set_top_light(1, lamp.model_copy(update={"cast_shadows": False}))
    np.testing.assert_array_equal(_shot(sim), _expected(0.0, INTENSITY))


WBT = """#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 16 }}
DirectionalLight {{ direction 1 0 0 intensity 0 ambientIntensity 0.3 }}
Solid {{
  translation 2 0 0
  children [ Shape {{ appearance PBRAppearance {{ baseColor 0.6 0.3 0.15 metalness 0 emissiveColor 0.05 0.4 0.7
                                                 emissiveIntensity {intensity} }} geometry Box {{ size 0.1 20 20 }} }} ]
}}
Robot {{ children [ Camera {{ name "cam" width 9 height 7 fieldOfView 1 }} ] controller "<none>" }}
"""


@pytest.mark.parametrize("intensity, used", [(0.5, 0.5), (-2, 1.0), (1, 1.0)])
def test_a_world_files_emissive_intensity_is_read(tmp_path: Path, intensity: float, used: float):
    """No light casts shadows (Webots' DirectionalLight castShadows defaults to FALSE): the forward
    shader's ``e·I``; a negative intensity is reset to 1 (WbPbrAppearance)."""
    path = tmp_path / "glow.wbt"
    path.write_text(WBT.format(intensity=intensity))
    got = wbt_image(path)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(0.3 * np.asarray(DIFFUSE) + used * np.asarray(GLOW)),
                                                       got.shape))


def _carried(casts: bool, glass: bool) -> LoadedWorld:
    """A bodiless robot whose camera faces a glowing wall (intensity 2.5; ``glass``: half transparent)
    under the ambient light and a point light it carries (casting shadows or not)."""
    dev = {"device": "Camera", "name": "cam", "width": 11, "height": 5, "field_of_view": 1.0}
    app = {"base_color": DIFFUSE, "emissive_color": GLOW, "emissive_intensity": INTENSITY,
           "transparency": 0.5 if glass else 0.0}
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False}, "lights": [AMBIENT],
        "solids": [{"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]},
                    "geometry": {"type": "box", "size": [0.1, 20, 20]}, "appearance": app}],
        "robots": [{"name": "bot", "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2,
                                                          "max_wheel_speed": 10.0},
                    "lights": [point(None, intensity=0.6, cast_shadows=casts)], "devices": [dev]}]})
    return LoadedWorld(world=w, source="<test>", base_dir=Path.cwd())


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("glass", [False, True])
@pytest.mark.parametrize("casts", [False, True])
def test_every_copy_applies_the_intensity_as_the_single_simulation(precision: str, casts: bool, glass: bool):
    x = [1.4, 0.9, -1.0]
    img = images_with_robot_placed(_carried(casts, glass), precision, "bot", [[xc, 0.0, 0.0] for xc in x])
    centre = img[:, 2, 5, 2::-1].astype(np.int64)          # its ray along +x meets the wall face on
    k = INTENSITY if glass or not casts else 1.0
    for c in range(len(x)):
        L = (0.5 if glass else 1.0) * (np.asarray(DIFFUSE) * (0.3 + 0.6) + k * np.asarray(GLOW))
        np.testing.assert_array_equal(centre[c], byte(L), err_msg=str(c))


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_an_leds_shadow_casting_light_changes_the_glow_in_the_copies_where_it_is_on(precision: str):
    """An LED at the camera holding a white point light that casts shadows (0.8, no attenuation), on in
    copy 0 only: there the centre pixel reads ``d·(0.3 + 0.8) + e``, in copy 1 (LED off, no light
    casting shadows) ``0.3·d + e·I``; each copy's bytes are its single simulation's."""
    from sensorium.server.sim.batched import BatchedSimulation
    led = {"device": "LED", "name": "led", "color": [[1.0, 1.0, 1.0]], "lights": [point(None, cast_shadows=True)]}
    lw = _carried(False, False)
    robot = lw.world.robots[0]
    robot = robot.model_validate({**robot.model_dump(mode="json", exclude_defaults=True), "lights": [],
                                  "devices": [*robot.model_dump(mode="json", exclude_defaults=True)["devices"], led]})
    lw = LoadedWorld(world=lw.world.model_copy(update={"robots": [robot]}), source="<test>", base_dir=Path.cwd())
    bs = BatchedSimulation(lw, 2, precision=precision)
    ref = bs.device("bot", "cam")
    bs.enable(ref, 8)
    bs.set_led(bs.slot("bot"), "led", 1, [0])
    singles = []
    for c in range(2):
        single = Simulation(lw, precision=precision)
        single.robot("bot").device("cam").enable(8)
        if c == 0:
            single.device("bot/led").set(1, single.time_ms)
        singles.append(single)
    img = stepped_alike(bs, ref, singles)
    d, e = np.asarray(DIFFUSE), np.asarray(GLOW)
    np.testing.assert_array_equal(img[0, 2, 5, 2::-1].astype(np.int64), byte(d * 1.1 + e))
    np.testing.assert_array_equal(img[1, 2, 5, 2::-1].astype(np.int64), byte(d * 0.3 + INTENSITY * e))


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_an_emissive_maps_texel_is_multiplied_by_the_intensity(tmp_path: Path, precision: str):
    """pbr.frag multiplies the emissiveColorMap's texel (as stored) by the intensity too: in a world
    without light (no light casts shadows) the box reads the resolve of ``I·texel/255``."""
    from PIL import Image
    Image.fromarray(np.full((2, 2, 3), MAP_TEXEL, dtype=np.uint8), "RGB").save(tmp_path / "m.png")
    app = {"base_color": DIFFUSE, "emissive_map": "m.png", "emissive_intensity": INTENSITY}
    sim = Simulation(world([], app), precision=precision, base_dir=tmp_path)
    got = _shot(sim)
    np.testing.assert_array_equal(got, np.broadcast_to(byte(INTENSITY * np.asarray(MAP_TEXEL) / 255.0), got.shape))
