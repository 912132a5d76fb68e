"""Webots' ``Shape.castShadows``: a shape with ``castShadows FALSE`` casts no shadow in a camera's
image (its light reaches what lies behind it), yet it is still seen: it hides what is behind it from
the camera, and every other ray kind meets it. Closed forms from test_camera's lit wall; the batched
camera is the single one's, byte for byte; a world where every shape casts shadows shares the
visual scenes (no extra build)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _protos import world_file

from sensorium.schemas import world as wm
from sensorium.server.raycast.engine import RayEngine
from sensorium.server.raycast.kinds import Precision, RayKind, ShapeEntry
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.world.geometry import Box, Pose
from sensorium.server.world.loader import LoadedWorld, load_world
from tests.test_camera import ALBEDO, WALL, expected_bytes, ray_hits_box, rays, rgb, shoot, world

CAM = {"width": 21, "height": 21, "field_of_view": 1.0}
LAMP = {"type": "PointLight", "location": [0.3, 0.0, 1.2], "intensity": 1.0, "ambient_intensity": 0.2,
        "cast_shadows": True}
CENTRE, HALF = np.array([1.0, 0.0, 0.6]), np.array([0.05, 0.1, 0.1])


def block(**extra) -> dict:
    return {"name": "block", "pose": {"translation": CENTRE.tolist()}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.2]},
            **extra}


def wall_points() -> np.ndarray:
    """Where each pixel's ray meets the wall's face (x = 1.95)."""
    d = rays(CAM)[0]
    return d * (1.95 / d[..., :1])


def shadow_of(z_low: float, z_high: float) -> np.ndarray:
    """The pixels whose wall point the block's slab z in (z_low, z_high) hides from the lamp: the
    segment to the lamp crosses |y| < 0.1 there, for x across the block's depth."""
    P, q = wall_points(), np.array(LAMP["location"])
    shadow = np.zeros(P.shape[:2], dtype=bool)
    for x in np.linspace(0.95, 1.05, 41):
        s = (x - P[..., 0]) / (q[0] - P[..., 0])
        y, z = P[..., 1] + s * (q[1] - P[..., 1]), P[..., 2] + s * (q[2] - P[..., 2])
        shadow |= (np.abs(y) < 0.1) & (z > z_low) & (z < z_high)
    return shadow


def wall_light() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each pixel's wall radiance unshadowed, where the block shadows the wall from the lamp, and
    which pixels see the block rather than the wall."""
    P = wall_points()
    v = np.array(LAMP["location"]) - P
    direct = -v[..., 0] / np.linalg.norm(v, axis=-1)
    return ALBEDO * (0.2 + direct)[..., None], shadow_of(0.5, 0.7), ray_hits_box(rays(CAM)[0], CENTRE, HALF)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_shape_without_cast_shadows_lets_the_light_through_and_is_still_seen(precision: str):
    lit, shadow, sees_block = wall_light()
    wall = ~sees_block
    assert (shadow & wall).sum() >= 6
    sim_on, on = shoot(world(CAM, [WALL, block()], [LAMP]), precision)
    sim_off, off = shoot(world(CAM, [WALL, block(cast_shadows=False)], [LAMP]), precision)
    np.testing.assert_array_equal(rgb(off)[wall], expected_bytes(lit)[wall])        # no shadow on the wall
    assert (rgb(on)[shadow & wall] < rgb(off)[shadow & wall]).all()                 # which the casting block has
    # the block itself (pixels well inside its outline) is drawn as before: it hides the wall
    inside = ray_hits_box(rays(CAM)[0], CENTRE, 0.8 * HALF)
    assert inside.sum() >= 3
    np.testing.assert_array_equal(rgb(off)[inside], rgb(on)[inside])
    assert (rgb(off)[inside] != expected_bytes(lit)[inside]).any(axis=-1).all()
    assert sim_off.counters["rays_camera"] == sim_on.counters["rays_camera"] > 21 * 21   # shadow rays still cast


def test_each_part_of_a_solid_keeps_its_own_flag():
    # two halves of the block as parts of one solid: only the upper one (z > 0.6) casts its shadow
    upper = {"pose": {"translation": [0, 0, 0.05]}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.1]}}
    lower = {"pose": {"translation": [0, 0, -0.05]}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.1]},
             "cast_shadows": False}
    halves = {"name": "halves", "pose": {"translation": CENTRE.tolist()}, "shapes": [upper, lower]}
    _, img = shoot(world(CAM, [WALL, halves], [LAMP]))
    lit, _, sees_block = wall_light()
    upper_shadow = shadow_of(0.6, 0.7)
    wall = ~sees_block & ~upper_shadow
    np.testing.assert_array_equal(rgb(img)[wall], expected_bytes(lit)[wall])
    shaded = ~sees_block & upper_shadow
    assert shaded.sum() >= 3
    np.testing.assert_array_equal(rgb(img)[shaded], np.broadcast_to(expected_bytes(ALBEDO * 0.2), (shaded.sum(), 3)))


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_batched_robot_without_cast_shadows_leaves_the_wall_lit_as_the_single_world_does(precision: str):
    # the wall lit by a directional light along (1, 0.5, 0); a blocker robot in copy 0 stands between
    # the wall's centre point and the light: its box casts no shadow, so both copies read the full term
    from tests.test_batched_camera import blocker_images
    img = blocker_images(precision, cast_shadows=False)
    full = np.floor(255.0 * (1.0 - np.exp(-np.array([0.6, 0.3, 0.15]) * (0.2 + 0.7 / math.sqrt(1.25)) * 1.3))
                    ** (1.0 / 2.2) + 0.5)
    assert (img[:, 2, 5, 2::-1] == full).all()


def test_shadow_rays_pass_a_non_caster_that_every_other_ray_kind_meets():
    eng = RayEngine(Precision.EXACT)
    box = Box((1.0, 1.0, 1.0))
    eng.add_body([ShapeEntry(box, Pose.identity(), True, True, casts_shadow=False)],
                 Pose(np.eye(3), np.array([3.0, 0.0, 0.0])))
    eng.add_body([ShapeEntry(box, Pose.identity(), True, True)], Pose(np.eye(3), np.array([6.0, 0.0, 0.0])))
    o, d = np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]])
    for kind in (RayKind.BOUNDING, RayKind.VISUAL):
        assert eng.cast(o, d, kind=kind).distance[0] == 2.5
    assert eng.cast(o, d, kind=RayKind.SHADOW).distance[0] == 5.5


def test_a_world_whose_shapes_all_cast_shadows_builds_no_scene_for_shadow_rays():
    eng = RayEngine(Precision.EXACT)
    eng.add_body([ShapeEntry(Box((1.0, 1.0, 1.0)), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([3.0, 0.0, 0.0])))
    o, d = np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]])
    eng.cast(o, d, kind=RayKind.VISUAL)
    builds = eng.counters["bvh_builds"]
    assert eng.cast(o, d, kind=RayKind.SHADOW).distance[0] == 2.5
    assert eng.counters["bvh_builds"] == builds


def test_webots_cast_shadows_false_is_read_from_a_wbt(tmp_path: Path):
    body = ('Solid { name "s" children [ Shape { castShadows FALSE geometry Box { size 1 1 1 } } '
            'Pose { translation 0 0 2 children [ Shape { geometry Sphere { radius 0.5 } } ] } ] }\n')
    loaded = load_world(world_file(tmp_path, body))
    parts = loaded.world.solids[0].shapes
    assert [p.cast_shadows for p in parts] == [False, True]


# ---- translucent shapes (WREN draws them in its translucent pass: they cast no shadow and take none)

def test_a_semi_transparent_or_alpha_textured_shape_casts_no_shadow(tmp_path: Path):
    from PIL import Image
    Image.new("RGBA", (2, 2), (200, 200, 200, 128)).save(tmp_path / "veil.png")
    lit, shadow, sees_block = wall_light()
    wall = ~sees_block
    for appearance in ({"transparency": 0.5}, {"texture": {"url": "veil.png"}}):
        _, img = shoot(world(CAM, [WALL, block(appearance=appearance)], [LAMP]), base_dir=tmp_path)
        np.testing.assert_array_equal(rgb(img)[wall], expected_bytes(lit)[wall])
    # an RGBA image whose alpha is 255 everywhere still makes the shape translucent (Webots tests
    # the image's format, not its pixels): no shadow; the same pixels as RGB shadow the wall
    Image.new("RGBA", (2, 2), (200, 200, 200, 255)).save(tmp_path / "opaque_rgba.png")
    _, img = shoot(world(CAM, [WALL, block(appearance={"texture": {"url": "opaque_rgba.png"}})], [LAMP]),
                   base_dir=tmp_path)
    np.testing.assert_array_equal(rgb(img)[wall], expected_bytes(lit)[wall])
    Image.new("RGB", (2, 2), (200, 200, 200)).save(tmp_path / "opaque_rgb.png")
    _, img = shoot(world(CAM, [WALL, block(appearance={"texture": {"url": "opaque_rgb.png"}})], [LAMP]),
                   base_dir=tmp_path)
    assert shadow[wall].any()
    assert (rgb(img)[shadow & wall] < expected_bytes(lit)[shadow & wall]).all()
    np.testing.assert_array_equal(rgb(img)[wall & ~shadow], expected_bytes(lit)[wall & ~shadow])


PANE_CAM = {"width": 5, "height": 5, "field_of_view": 0.3}
SUN = {"type": "DirectionalLight", "direction": [1, 0, -1], "intensity": 0.6, "ambient_intensity": 0.2,
       "cast_shadows": True}
PANE_COLOUR = np.array([0.1, 0.9, 0.2])


def pane_world(transparency: float) -> dict:
    """The camera looks along +x at a pane (x = 1) before the wall (x = 2); the sun shines along
    (1, 0, -1) over a blocker above the view (x = 0.5, z in [0.3, 0.7]) that stands between the
    pane and the sun, never between the wall and the sun."""
    pane = {"name": "pane", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.02, 1, 0.5]},
            "appearance": {"base_color": PANE_COLOUR.tolist(), "transparency": transparency}}
    blocker = {"name": "blocker", "pose": {"translation": [0.5, 0, 0.5]}, "geometry": {"type": "box", "size": [0.1, 2, 0.4]}}
    return {"world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [WALL, pane, blocker], "lights": [SUN],
            "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **PANE_CAM}]}]}


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_semi_transparent_surface_takes_no_shadow_single_and_batched(precision: str):
    direct = 0.2 + 0.6 / math.sqrt(2.0)               # ambient + intensity N.L, N.L = 1/sqrt(2) on both faces
    data = pane_world(0.4)
    _, img = shoot(wm.World.model_validate(data), precision)
    want = expected_bytes(0.6 * PANE_COLOUR * direct + 0.4 * ALBEDO * direct)
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(want, (5, 5, 3)))
    # an opaque pane in the same place takes the blocker's shadow: the ambient term alone
    _, opaque = shoot(wm.World.model_validate(pane_world(0.0)), precision)
    np.testing.assert_array_equal(rgb(opaque), np.broadcast_to(expected_bytes(PANE_COLOUR * 0.2), (5, 5, 3)))
    lw = LoadedWorld(world=wm.World.model_validate(data), source="<test>", base_dir=Path.cwd())
    bs = BatchedSimulation(lw, 2, precision=precision)
    ref = bs.device("r", "cam")
    bs.enable(ref, 16)
    bs.step()
    for c in range(2):
        assert bs.image(ref)[c].tobytes() == img.tobytes(), c


def textured_pane_world(url: str) -> dict:
    """pane_world's opaque pane, white-textured (the texel is 1 in linear: the albedo stays its colour)."""
    data = pane_world(0.0)
    data["solids"][1]["appearance"]["texture"] = {"url": url}
    return data


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_an_rgba_image_all_opaque_makes_its_surface_take_no_shadow_single_and_batched(precision: str, tmp_path: Path):
    from PIL import Image
    Image.new("RGBA", (2, 2), (255, 255, 255, 255)).save(tmp_path / "white_rgba.png")
    Image.new("RGB", (2, 2), (255, 255, 255)).save(tmp_path / "white_rgb.png")
    direct = 0.2 + 0.6 / math.sqrt(2.0)
    # the RGBA pane: drawn as translucent (alpha 1: its own colour, no blend), lit by the sun unshadowed
    data = textured_pane_world("white_rgba.png")
    _, img = shoot(wm.World.model_validate(data), precision, base_dir=tmp_path)
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(PANE_COLOUR * direct), (5, 5, 3)))
    # the RGB pane of the same pixels takes the blocker's shadow: the ambient term alone
    _, opaque = shoot(wm.World.model_validate(textured_pane_world("white_rgb.png")), precision, base_dir=tmp_path)
    np.testing.assert_array_equal(rgb(opaque), np.broadcast_to(expected_bytes(PANE_COLOUR * 0.2), (5, 5, 3)))
    for d, ref_img in ((data, img), (textured_pane_world("white_rgb.png"), opaque)):
        lw = LoadedWorld(world=wm.World.model_validate(d), source="<test>", base_dir=tmp_path)
        bs = BatchedSimulation(lw, 2, precision=precision)
        ref = bs.device("r", "cam")
        bs.enable(ref, 16)
        bs.step()
        for c in range(2):
            assert bs.image(ref)[c].tobytes() == ref_img.tobytes(), c


def test_only_the_image_format_decides_translucency(tmp_path: Path):
    from PIL import Image

    from sensorium.server.sim.scene import translucent
    from sensorium.server.world.textures import load_alpha, load_image, uses_alpha
    Image.new("RGBA", (2, 2), (10, 20, 30, 255)).save(tmp_path / "a.png")
    Image.new("RGB", (2, 2), (10, 20, 30)).save(tmp_path / "b.png")
    Image.new("LA", (2, 2), (10, 255)).save(tmp_path / "c.png")
    assert uses_alpha(tmp_path / "a.png") and uses_alpha(tmp_path / "c.png") and not uses_alpha(tmp_path / "b.png")
    # the colours are the RGB image's; no see-through texel to composite
    assert load_alpha(tmp_path / "a.png") is None
    np.testing.assert_array_equal(load_image(tmp_path / "a.png"), load_image(tmp_path / "b.png"))
    rgba = wm.Appearance.model_validate({"texture": {"url": "a.png"}})
    plain = wm.Appearance.model_validate({"texture": {"url": "b.png"}})
    assert translucent(rgba, tmp_path) and not translucent(plain, tmp_path)
