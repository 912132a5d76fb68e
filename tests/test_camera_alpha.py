"""Texture alpha in camera images, against closed forms: Webots draws an ImageTexture whose image
has an alpha channel translucent, its final alpha ``(1 − transparency)·texel alpha`` (phong.frag,
pbr.frag). A quad half alpha 0 / half opaque in front of a wall shows the wall exactly (what a camera
of the wall alone renders) through the clear half and the texel colour on the other; a 50 % texel
blends; material transparency multiplies in; the batched camera gives the single camera's bytes;
range finders see alpha-textured shapes as opaque (Webots' reference: "as if they were not
transparent")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld
from tests.test_camera import ALBEDO, WALL, expected_bytes, rgb, shoot, world

CAM = {"width": 6, "height": 6, "field_of_view": 0.6}
AMBIENT = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.5}
BLUE = (20, 60, 230)


def _lin(c) -> np.ndarray:
    c = np.asarray(c, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _quad(texture: str, transparency: float = 0.0, geometry: dict | None = None) -> dict:
    """A 4 m quad at x = 1 facing the camera (a plane turned so its normal is −x), textured."""
    rot = {} if geometry is not None else {"rotation": [0, 1, 0, -math.pi / 2]}
    return {"name": "quad", "pose": {"translation": [1.0, 0, 0], **rot},
            "geometry": geometry or {"type": "plane", "size": [4, 4]},
            "appearance": {"base_color": [1, 1, 1], "texture": texture, "transparency": transparency}}


@pytest.fixture
def images(tmp_path: Path) -> Path:
    from PIL import Image
    half = np.zeros((1, 2, 4), dtype=np.uint8)                   # texel 0: alpha 0 (its colour red), texel 1: opaque blue
    half[0, 0] = (255, 0, 0, 0)
    half[0, 1] = (*BLUE, 255)
    Image.fromarray(half, "RGBA").save(tmp_path / "half.png")
    Image.fromarray(np.full((2, 2, 4), (*BLUE, 128), dtype=np.uint8), "RGBA").save(tmp_path / "fifty.png")
    Image.fromarray(np.full((2, 2, 4), (*BLUE, 255), dtype=np.uint8), "RGBA").save(tmp_path / "solid.png")
    return tmp_path


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_a_half_clear_quad_shows_the_wall_through_its_clear_half_and_its_texel_on_the_other(images, precision):
    _, wall_alone = shoot(world(CAM, [WALL], [AMBIENT]), precision)
    _, img = shoot(world(CAM, [WALL, _quad("half.png")], [AMBIENT]), precision, base_dir=images)
    wall = np.broadcast_to(expected_bytes(0.5 * ALBEDO), (6, 3))
    texel = np.broadcast_to(expected_bytes(0.5 * _lin(BLUE)), (6, 3))
    np.testing.assert_array_equal(rgb(wall_alone), np.broadcast_to(wall, (6, 6, 3)))
    # the plane's u runs along its local x (world +z after the turn): texel 0 is the image's lower half
    np.testing.assert_array_equal(img[3:], wall_alone[3:])       # alpha 0: the wall, bit for bit
    np.testing.assert_array_equal(rgb(img)[:3], np.broadcast_to(texel, (3, 6, 3)))


@pytest.mark.parametrize("transparency", [0.0, 0.4])
def test_a_half_transparent_texel_blends_with_the_material_transparency(images, transparency):
    """alpha = (1 − transparency)·128/255: L = alpha·texel + (1 − alpha)·wall (ambient 0.5)."""
    _, img = shoot(world(CAM, [WALL, _quad("fifty.png", transparency)], [AMBIENT]), base_dir=images)
    a = (1.0 - transparency) * 128 / 255
    L = 0.5 * (a * _lin(BLUE) + (1.0 - a) * ALBEDO)
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(L), (6, 6, 3)))


def test_an_opaque_alpha_channel_and_a_box_of_clear_texels(images):
    """Alpha 255 everywhere draws as an RGB image does; a box textured with alpha 0 shows the wall
    (its far faces, as back-face culling, are not seen either)."""
    _, rgba = shoot(world(CAM, [WALL, _quad("solid.png")], [AMBIENT]), base_dir=images)
    np.testing.assert_array_equal(rgb(rgba), np.broadcast_to(expected_bytes(0.5 * _lin(BLUE)), (6, 6, 3)))
    from PIL import Image
    Image.fromarray(np.zeros((2, 2, 4), dtype=np.uint8), "RGBA").save(images / "clear.png")
    box = _quad("clear.png", geometry={"type": "box", "size": [0.3, 4, 4]})
    _, wall_alone = shoot(world(CAM, [WALL], [AMBIENT]))
    _, img = shoot(world(CAM, [WALL, box], [AMBIENT]), base_dir=images)
    np.testing.assert_array_equal(img, wall_alone)


def test_range_finders_see_alpha_textured_shapes_as_opaque(images):
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 16}, "solids": [WALL, _quad("half.png")],
        "robots": [{"name": "r", "devices": [{"device": "RangeFinder", "name": "depth", "width": 6, "height": 6,
                                              "field_of_view": 0.6, "max_range": 5}]}]})
    sim = Simulation(w, base_dir=images)
    rf = sim.device("r/depth")
    rf.enable(16)
    sim.run(1)
    np.testing.assert_allclose(rf.range_image, 1.0, rtol=1e-6)


@pytest.mark.parametrize("precision", ["exact", "fast"])
@pytest.mark.parametrize("texture", ["half.png", "fifty.png"])
def test_batched_copies_render_alpha_as_the_single_camera(images, precision, texture):
    """Two copies, the robot (carrying a thin box textured with 50 % alpha in view) turned differently
    in each: each copy's image equals a Simulation's with that copy's pose, byte for byte (the plate
    and the quad seen through each other)."""
    plate = {"name": "plate", "pose": {"translation": [0.6, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.01, 0.3, 0.3]},
             "appearance": {"base_color": [1, 1, 1], "texture": "fifty.png"}}
    w = world({**CAM, "width": 12, "height": 10, "field_of_view": 1.0}, [WALL, _quad(texture, 0.2)], [AMBIENT])
    w = w.model_copy(update={"robots": [w.robots[0].model_copy(update={"shapes": [wm.Part.model_validate(plate)]})]})
    yaws = [0.0, 0.3]
    bs = BatchedSimulation(LoadedWorld(world=w, source="<test>", base_dir=images), len(yaws), precision=precision)
    for c, yaw in enumerate(yaws):
        bs.set_pose(c, 0, rotation=[0, 0, 1, yaw])
    ref = bs.device("r", "cam")
    bs.enable(ref, 16)
    bs.step()
    corner = rgb(bs.image(ref)[0])[9, 0]          # copy 0, a lower corner: the quad alone over the wall
    a = 0.0 if texture == "half.png" else 0.8 * 128 / 255
    np.testing.assert_array_equal(corner, expected_bytes(0.5 * (a * _lin(BLUE) + (1.0 - a) * ALBEDO)))
    for c, yaw in enumerate(yaws):
        r = w.robots[0]
        wc = w.model_copy(update={"robots": [r.model_copy(update={"pose": r.pose.model_copy(
            update={"rotation": [0, 0, 1, yaw]})})]})
        _, want = shoot(wc, precision, base_dir=images)
        assert want.tobytes() == bs.image(ref)[c].tobytes(), c
        assert len(np.unique(want.reshape(-1, 4), axis=0)) >= (3 if texture == "half.png" else 2)   # the plate in view


@pytest.mark.parametrize("quads", [8, 9])
def test_past_eight_see_through_layers_the_next_surface_is_drawn_opaque(images, quads):
    """MAX_LAYERS = 8: a ray goes on past 8 clear texels (the wall behind shows); a 9th clear quad in
    its way is drawn with its texel's colour (red, whose alpha is 0), never cast past."""
    from PIL import Image

    from sensorium.server.sim.cameras import MAX_LAYERS
    assert MAX_LAYERS == 8
    Image.fromarray(np.full((2, 2, 4), (255, 0, 0, 0), dtype=np.uint8), "RGBA").save(images / "red_clear.png")
    stack = [{**_quad("red_clear.png"), "name": f"q{i}", "pose": {"translation": [1.0 + 0.05 * i, 0, 0],
                                                                  "rotation": [0, 1, 0, -math.pi / 2]}}
             for i in range(quads)]
    sim, img = shoot(world(CAM, [WALL, *stack], [AMBIENT]), base_dir=images)
    want = 0.5 * ALBEDO if quads == 8 else 0.5 * _lin((255, 0, 0))
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(want), (6, 6, 3)))
    assert sim.counters["rays_camera"] == 36 * (quads + 1 if quads == 8 else quads)
