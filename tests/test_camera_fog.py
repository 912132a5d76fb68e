"""Webots' Fog in camera images against closed-form answers: a wall at known distances in a world
with each fog type has, pixel by pixel, the colour the light model gives mixed with the fog's
linear colour by ``(1 − f(d))^2.2`` (WREN's pbr/phong shaders, ``d`` the hit's distance from the
camera) before the HDR resolve; semi-transparent surfaces are each fogged at their own distance;
the background is not fogged; a world without fog (or with a visibility range of 0) keeps its bits;
range images and the segmentation image are not fogged; bad fog fields are one clear line each;
a .wbt Fog node is read (the first one only, Webots' resets with warnings)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
        "appearance": {"base_color": [0.8, 0.5, 0.2]}, "recognition_colors": [[0.0, 1.0, 0.0]]}
ALBEDO = np.array([0.8, 0.5, 0.2])
AMBIENT = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 1.0}
FOG_COLOR = [0.02, 0.5, 0.9]          # one component on each side of the sRGB curve's knee (0.04045)
FOG_LINEAR = np.array([0.02 / 12.92, ((0.5 + 0.055) / 1.055) ** 2.4, ((0.9 + 0.055) / 1.055) ** 2.4])
CAM = {"width": 9, "height": 7, "field_of_view": 1.0}


def world(cam: dict, fog: dict | None, solids=(WALL,), lights=(AMBIENT,), devices=(), **extra) -> wm.World:
    data = {"world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": list(solids), "lights": list(lights),
            "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **cam}, *devices]}], **extra}
    if fog is not None:
        data["fog"] = fog
    return wm.World.model_validate(data)


def shoot(w: wm.World) -> np.ndarray:
    sim = Simulation(w, precision="exact")
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    return cam.image[:, :, [2, 1, 0]].astype(np.int64)


def expected_bytes(L: np.ndarray) -> np.ndarray:
    """round(255 (1 − e^(−L))^(1/2.2)): Webots' HDR resolve at exposure 1, 8 bits."""
    return np.floor(255.0 * (1.0 - np.exp(-np.asarray(L))) ** (1.0 / 2.2) + 0.5).astype(np.int64)


def wall_distances(cam: dict) -> np.ndarray:
    """Each pixel ray's distance from the camera (at the origin, looking along +x) to the wall's face x = 1.95."""
    c = wm.Camera.model_validate({"device": "Camera", "name": "x", **cam})
    d = imaging.pixel_directions(imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection))[0]
    return 1.95 / d[..., 0]


def fog_share(d: np.ndarray, visibility: float, fog_type: str) -> np.ndarray:
    f = {"LINEAR": (visibility - d) / visibility, "EXPONENTIAL": np.exp(-d / visibility),
         "EXPONENTIAL2": np.exp(-((d / visibility) ** 2))}[fog_type]
    return (1.0 - np.clip(f, 0.0, 1.0)) ** 2.2


@pytest.mark.parametrize("fog_type,visibility", [("LINEAR", 2.1), ("LINEAR", 6.0), ("EXPONENTIAL", 3.0),
                                                 ("EXPONENTIAL2", 2.5)])
def test_a_wall_is_mixed_with_the_fog_colour_by_its_distance(fog_type, visibility):
    fog = {"color": FOG_COLOR, "visibility_range": visibility, "fog_type": fog_type}
    got = shoot(world(CAM, fog))
    d = wall_distances(CAM)
    w = fog_share(d, visibility, fog_type)[..., None]
    want = expected_bytes(ALBEDO * (1.0 - w) + FOG_LINEAR * w)
    np.testing.assert_array_equal(got, want)
    clear = shoot(world(CAM, None))
    np.testing.assert_array_equal(clear, np.broadcast_to(expected_bytes(ALBEDO), clear.shape))
    assert np.all(np.abs(got - clear).max(axis=-1) > 0)          # every pixel is fogged
    assert len({tuple(p) for p in got.reshape(-1, 3)}) >= 5       # by its own distance: a gradient
    if fog_type == "LINEAR" and visibility < d.max():             # beyond the visibility range: all fog
        beyond = d >= visibility
        assert beyond.any() and not beyond.all()
        np.testing.assert_array_equal(got[beyond], np.broadcast_to(expected_bytes(FOG_LINEAR), got[beyond].shape))


def test_the_background_is_not_fogged_and_a_visibility_range_of_zero_is_no_fog():
    sky = {"sky_color": [0.2, 0.4, 1.0]}
    cam = {**CAM, "far": 1.0}                   # the wall is beyond the far plane: only the background
    fog = {"color": FOG_COLOR, "visibility_range": 0.5}
    got = shoot(world(cam, fog, background=sky))
    np.testing.assert_array_equal(got, np.broadcast_to([51, 102, 255], got.shape))     # the sky colour's bytes
    # visibility 0: Webots turns the fog off; the same bits as no fog, nothing computed for it
    w0 = world(CAM, {"color": FOG_COLOR, "visibility_range": 0.0, "fog_type": "EXPONENTIAL"})
    assert Simulation(w0).scene.fog is None and Simulation(world(CAM, None)).scene.fog is None
    np.testing.assert_array_equal(shoot(w0), shoot(world(CAM, None)))


def test_semi_transparent_surfaces_are_each_fogged_at_their_own_distance():
    # one ray along +x: a 40 % transparent pane's face at 0.99 m, the wall's at 1.95 m
    cam = {"width": 1, "height": 1, "field_of_view": 0.1}
    pane = {"name": "pane", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.02, 4, 4]},
            "appearance": {"base_color": [0.1, 0.9, 0.2], "transparency": 0.4}}
    fog = {"color": FOG_COLOR, "visibility_range": 2.0, "fog_type": "EXPONENTIAL"}
    got = shoot(world(cam, fog, solids=(WALL, pane)))
    w1, w2 = fog_share(np.array(0.99), 2.0, "EXPONENTIAL"), fog_share(np.array(1.95), 2.0, "EXPONENTIAL")
    L = 0.6 * (np.array([0.1, 0.9, 0.2]) * (1 - w1) + FOG_LINEAR * w1) + 0.4 * (ALBEDO * (1 - w2) + FOG_LINEAR * w2)
    np.testing.assert_array_equal(got[0, 0], expected_bytes(L))


def test_range_images_and_the_segmentation_image_are_not_fogged():
    cam = {**CAM, "recognition": {"segmentation": True}}
    rf = {"device": "RangeFinder", "name": "depth", "width": 9, "height": 7, "field_of_view": 1.0, "max_range": 5.0}
    out = []
    for fog in (None, {"color": FOG_COLOR, "visibility_range": 1.0, "fog_type": "EXPONENTIAL2"}):
        sim = Simulation(world(cam, fog, devices=[rf]))
        camera, depth = sim.device("r/cam"), sim.device("r/depth")
        camera.enable(16)
        camera.recognition_enable(16)
        camera.enable_segmentation(True)
        depth.enable(16)
        sim.run(1)
        out.append((camera.image.copy(), camera.segmentation_image.copy(), depth.range_image.copy()))
    (img0, seg0, rng0), (img1, seg1, rng1) = out
    assert not np.array_equal(img0, img1)                          # the colour image is fogged
    np.testing.assert_array_equal(seg0, seg1)
    assert np.all(seg1[:, :, 1] == 255)                           # the wall's recognition colour, untouched
    np.testing.assert_array_equal(rng0, rng1)
    np.testing.assert_allclose(rng1, 1.95, rtol=1e-6)             # planar depth of the wall's face


@pytest.mark.parametrize("fog,field,message", [
    ({"fog_type": "FOGGY"}, "fog.fog_type", "'LINEAR', 'EXPONENTIAL' or 'EXPONENTIAL2'"),
    ({"visibility_range": -1.0}, "fog.visibility_range", "greater than or equal to 0"),
    ({"color": [0.5, 1.5, 0.0]}, "fog.color", "within [0, 1]"),
    ({"density": 0.3}, "fog.density", "unknown key"),
])
def test_bad_fog_fields_are_one_clear_line(fog, field, message):
    with pytest.raises(WorldError) as info:
        parse_world({"fog": fog}, source="w.yaml", base_dir=Path.cwd())
    problems = [(p.path, p.message) for p in info.value.problems]
    assert len(problems) == 1 and problems[0][0] == field and message in problems[0][1], problems
    assert len(str(info.value).splitlines()) == 1 and str(info.value).startswith("w.yaml: fog.")


WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Background { skyColor [ 0.2 0.4 1 ] }
Fog { color 0.02 0.5 0.9 visibilityRange 2.5 fogType "exponential2" }
Fog { color 1 0 0 visibilityRange 1 }
DirectionalLight { direction 1 0 0 intensity 0 ambientIntensity 1 }
Solid { translation 2 0 0 name "wall"
        children [ Shape { appearance PBRAppearance { baseColor 0.8 0.5 0.2 } geometry Box { size 0.1 20 20 } } ] }
Robot { name "r" children [ Camera { name "cam" width 9 height 7 fieldOfView 1 } ] }
"""


def test_a_wbt_fog_node_is_read_the_first_one_only(tmp_path: Path):
    p = tmp_path / "w.wbt"
    p.write_text(WBT)
    loaded = load_world(p)
    assert loaded.world.fog == wm.Fog(color=(0.02, 0.5, 0.9), visibility_range=2.5, fog_type="EXPONENTIAL2")
    assert any("only the first Fog node" in m and "w.wbt:5:" in m for m in loaded.warnings), loaded.warnings
    assert not any("skipped nodes" in m and "Fog" in m for m in loaded.warnings), loaded.warnings
    # the camera of that world sees the wall through it, as the YAML fog does
    yaml_fog = {"color": FOG_COLOR, "visibility_range": 2.5, "fog_type": "EXPONENTIAL2"}
    sim = Simulation(loaded.world, precision="exact")
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    # the .wbt camera looks along +x from the origin like the YAML one (Webots' FLU camera frame)
    np.testing.assert_array_equal(cam.image[:, :, [2, 1, 0]].astype(np.int64), shoot(world(CAM, yaml_fog)))


@pytest.mark.parametrize("fields,warning,fog", [
    ('fogType "DENSE" visibilityRange 2', "unknown Fog fogType 'DENSE': LINEAR", ((1.0, 1.0, 1.0), 2.0, "LINEAR")),
    ("visibilityRange -3", "visibilityRange -3 < 0 reset to 0", ((1.0, 1.0, 1.0), 0.0, "LINEAR")),
    ("color 1.5 0.5 -1 visibilityRange 4", "clamped to [0, 1]", ((1.0, 0.5, 0.0), 4.0, "LINEAR")),
])
def test_a_wbt_fog_gets_webots_resets_with_a_warning(tmp_path: Path, fields, warning, fog):
    p = tmp_path / "w.wbt"
    p.write_text(f"#VRML_SIM R2023b utf8\nWorldInfo {{ }}\nFog {{ {fields} }}\n")
    loaded = load_world(p)
    f = loaded.world.fog
    assert f is not None and (f.color, f.visibility_range, f.fog_type) == fog
    assert sum(warning in m for m in loaded.warnings) == 1, loaded.warnings


def test_the_readme_fog_example_is_a_valid_world():
    import yaml

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    blocks = [b.split("```", 1)[0] for b in readme.split("```yaml\n")[1:]]
    (text,) = [b for b in blocks if b.startswith("fog:")]
    loaded = parse_world(yaml.safe_load(text), source="README", base_dir=Path.cwd())
    assert loaded.world.fog == wm.Fog(color=(0.7, 0.7, 0.75), visibility_range=8.0, fog_type="EXPONENTIAL")
    assert Simulation(loaded.world).scene.fog is not None
