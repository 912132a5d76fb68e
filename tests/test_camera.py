"""Camera (issue 23) against closed-form answers: a pixel that sees a flat lit wall has the colour
the light model gives (point and spot lights, attenuation, ambient), shadows of the lights that cast
them, semi-transparent surfaces composited front to back, textures, the background, anti-aliasing
as supersampling, exposure, noise and determinism, laziness, the bgra8 topics, and the Python API."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import imaging
from sensorium.server.sim.simulation import Simulation


def world(cam: dict, solids=(), lights=(), **extra) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5},
        "solids": list(solids), "lights": list(lights),
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **cam}]}], **extra})


def shoot(w: wm.World, precision="exact", steps=1, base_dir=None) -> tuple[Simulation, np.ndarray]:
    sim = Simulation(w, precision=precision, base_dir=base_dir)
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(steps)
    return sim, cam.image


def rgb(image: np.ndarray) -> np.ndarray:
    """(H, W, 3) red, green, blue of a BGRA image."""
    return image[:, :, [2, 1, 0]].astype(np.int64)


def expected_bytes(L: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """Webots' HDR resolve and 8-bit conversion, written out: round(255 (1 - e^(-L x))^(1/2.2))."""
    return np.floor(255.0 * (1.0 - np.exp(-np.asarray(L) * exposure)) ** (1.0 / 2.2) + 0.5).astype(np.int64)


def rays(cam: dict, samples=imaging.SAMPLES_CENTRE) -> np.ndarray:
    c = wm.Camera.model_validate({"device": "Camera", "name": "x", **cam})
    return imaging.pixel_directions(imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection), samples)


def ray_hits_box(d: np.ndarray, centre: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Whether rays from the origin along ``d`` (..., 3) meet an axis-aligned box (slab test)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (centre - half) / d, (centre + half) / d
    lo, hi = np.minimum(t1, t2).max(axis=-1), np.maximum(t1, t2).min(axis=-1)
    return (hi >= lo) & (hi > 0)


WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
        "appearance": {"base_color": [0.8, 0.5, 0.2]}}
ALBEDO = np.array([0.8, 0.5, 0.2])


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_a_flat_wall_lit_by_a_point_light_has_the_light_models_colour(precision):
    # a point light 1 m ahead (attenuation 1/d²): every pixel of the wall face (x = 1.95) is
    # albedo · I · cos / d² with cos and d from the hit point to the light
    cam = {"width": 9, "height": 7, "field_of_view": 1.0}
    light = {"type": "PointLight", "location": [1.0, 0.3, -0.2], "intensity": 1.5, "attenuation": [0, 0, 1],
             "color": [1.0, 0.9, 0.8]}
    _, img = shoot(world(cam, [WALL], [light]), precision)
    d = rays(cam)[0]
    P = d * (1.95 / d[..., :1])
    v = np.array(light["location"]) - P
    dist = np.linalg.norm(v, axis=-1)
    cos = v[..., 0] * -1.0 / dist            # the wall's normal towards the camera: -x
    L = ALBEDO * (1.5 * cos / dist**2)[..., None] * np.array(light["color"])
    want = expected_bytes(L)
    assert np.all(img[:, :, 3] == 255)
    np.testing.assert_array_equal(rgb(img), want)
    assert len(np.unique(want[..., 0])) > 10           # a gradient, not a constant


def test_a_large_image_is_shaded_in_blocks_on_threads_with_the_same_closed_form_pixels():
    # 320 x 240 = 76,800 pixels: radiance in blocks of shading.BLOCK rows, on 1 or 2 threads (the
    # blocks side by side): the closed-form wall of the test above, and the same bytes either way
    from sensorium.server.devices import shading

    cam = {"width": 320, "height": 240, "field_of_view": 1.0}
    assert cam["width"] * cam["height"] > 2 * shading.BLOCK
    light = {"type": "PointLight", "location": [1.0, 0.3, -0.2], "intensity": 1.5, "attenuation": [0, 0, 1],
             "color": [1.0, 0.9, 0.8]}
    d = rays(cam)[0]
    P = d * (1.95 / d[..., :1])
    v = np.array(light["location"]) - P
    dist = np.linalg.norm(v, axis=-1)
    want = expected_bytes(ALBEDO * (1.5 * (-v[..., 0] / dist) / dist**2)[..., None] * np.array(light["color"]))
    images = []
    for threads in (1, 2):
        sim = Simulation(world(cam, [WALL], [light]), precision="exact")
        sim.scene.engine.threads = threads
        camera = sim.device("r/cam")
        camera.enable(16)
        sim.run(1)
        images.append(camera.image.copy())
    np.testing.assert_array_equal(rgb(images[0]), want)
    assert images[0].tobytes() == images[1].tobytes()


def test_spot_light_cut_off_and_ambient():
    cam = {"width": 31, "height": 31, "field_of_view": 1.2}
    spot = {"type": "SpotLight", "location": [0.5, 0.0, 0.0], "direction": [1, 0, 0], "intensity": 2.0,
            "beam_width": 0.15, "cut_off_angle": 0.3, "attenuation": [1, 0, 0], "ambient_intensity": 0.05}
    _, img = shoot(world(cam, [WALL], [spot]))
    d = rays(cam)[0]
    P = d * (1.95 / d[..., :1])
    v = np.array([0.5, 0.0, 0.0]) - P
    dist = np.linalg.norm(v, axis=-1)
    alpha = np.arccos(np.clip(-v[..., 0] / dist, -1, 1))        # angle off the spot's axis
    spot_f = np.where(alpha > 0.3, 0.0, np.where(alpha <= 0.15, 1.0, (alpha - 0.3) / (0.15 - 0.3)))
    cos = -v[..., 0] / dist
    L = ALBEDO * (0.05 + 2.0 * cos * spot_f)[..., None]
    got = rgb(img)
    want = expected_bytes(L)
    # pixels on the beam's edges (alpha within float rounding of a cut-off) may take either side
    edge = (np.abs(alpha - 0.3) < 1e-9) | (np.abs(alpha - 0.15) < 1e-9)
    np.testing.assert_array_equal(got[~edge], want[~edge])
    assert (spot_f == 0).sum() > 100 and (spot_f == 1).sum() > 20 and ((spot_f > 0) & (spot_f < 1)).sum() > 20


def test_shadows_only_from_lights_that_cast_them():
    # a block between the lamp and the wall: with cast_shadows its shadow has only the ambient term
    cam = {"width": 21, "height": 21, "field_of_view": 1.0}
    block = {"name": "block", "pose": {"translation": [1.0, 0.0, 0.6]}, "geometry": {"type": "box", "size": [0.1, 0.2, 0.2]}}
    lamp = {"type": "PointLight", "location": [0.3, 0.0, 1.2], "intensity": 1.0, "ambient_intensity": 0.2,
            "cast_shadows": True}
    sim, img = shoot(world(cam, [WALL, block], [lamp]))
    d = rays(cam)[0]
    P = d * (1.95 / d[..., :1])
    # the segment from each wall point to the lamp: does it cross the block (|y| < 0.1, |z-0.6| < 0.1 at x in [0.95, 1.05])?
    q = np.array(lamp["location"])
    shadow = np.zeros(P.shape[:2], dtype=bool)
    for x in np.linspace(0.95, 1.05, 41):
        s = (x - P[..., 0]) / (q[0] - P[..., 0])
        y, z = P[..., 1] + s * (q[1] - P[..., 1]), P[..., 2] + s * (q[2] - P[..., 2])
        shadow |= (np.abs(y) < 0.1) & (np.abs(z - 0.6) < 0.1)
    v = q - P
    dist = np.linalg.norm(v, axis=-1)
    direct = -v[..., 0] / dist
    sees_block = ray_hits_box(d, np.array([1.0, 0.0, 0.6]), np.array([0.05, 0.1, 0.1]))
    L = ALBEDO * (0.2 + np.where(shadow, 0.0, direct))[..., None]
    got, want = rgb(img), expected_bytes(L)
    wall = ~sees_block
    np.testing.assert_array_equal(got[wall], want[wall])
    assert (shadow & wall).sum() >= 6
    assert sim.counters["rays_camera"] > 21 * 21                     # shadow rays were cast
    # the same light without cast_shadows lights the shadow's pixels too
    lamp2 = {**lamp, "cast_shadows": False}
    sim2, img2 = shoot(world(cam, [WALL, block], [lamp2]))
    L2 = ALBEDO * (0.2 + direct)[..., None]
    np.testing.assert_array_equal(rgb(img2)[wall], expected_bytes(L2)[wall])
    assert sim2.counters["rays_camera"] == 21 * 21


@pytest.mark.parametrize("pane_geometry", [{"type": "box", "size": [0.02, 4, 4]}, {"type": "plane", "size": [4, 4]}])
def test_semi_transparent_surfaces_are_composited_front_to_back(pane_geometry):
    # a 40 % transparent green pane at x = 1, an ambient-only light: pixel = 0.6 green + 0.4 wall,
    # seen through the pane's front face only (a box's back face is not blended: back-face culling)
    cam = {"width": 5, "height": 5, "field_of_view": 0.6}
    rot = {"rotation": [0, 1, 0, -math.pi / 2]} if pane_geometry["type"] == "plane" else {}   # plane normal -> -x
    pane = {"name": "pane", "pose": {"translation": [1.0, 0, 0], **rot}, "geometry": pane_geometry,
            "appearance": {"base_color": [0.1, 0.9, 0.2], "transparency": 0.4}}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.5}
    _, img = shoot(world(cam, [WALL, pane], [amb]))
    L = 0.5 * (0.6 * np.array([0.1, 0.9, 0.2]) + 0.4 * ALBEDO)
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(L), (5, 5, 3)))


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("yaw", [0.0, 0.95])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (5e3, -5e3)])
def test_a_half_transparent_box_wall_is_seen_once_at_every_pixel(precision, yaw, offset):
    """A 0.1 m thick, 400 m wide half-transparent box wall turned by ``yaw`` 2 m before the camera, over
    the black sky, lit by the ambient 0.3 and a point light at the camera (0.8·cos of each ray's
    incidence): every pixel reads the resolve of 0.5·d·(0.3 + 0.8·cos), its front face composited once
    and its back face culled, up to grazing incidence (cos 0.049 at the turned wall's edge) and 7 km
    from the origin. FAST's float32 start past the front face once landed short of it at oblique pixels,
    which met the face again, took it for the far face and the far face for a new one (23 to 40 levels
    too bright)."""
    cam = {"width": 15, "height": 11, "field_of_view": 1.2}
    d = np.array([0.6, 0.3, 0.15])
    wall = {"name": "wall", "pose": {"translation": [2.0 + offset[0], offset[1], 0.0], "rotation": [0, 0, 1, yaw]},
            "geometry": {"type": "box", "size": [0.1, 400, 400]}, "appearance": {"base_color": d.tolist(),
                                                                               "transparency": 0.5}}
    lights = [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.3},
              {"type": "PointLight", "location": [offset[0], offset[1], 0.0], "intensity": 0.8}]
    _, img = shoot(wm.World.model_validate({
        "world_info": {"basic_time_step": 16}, "solids": [wall], "lights": lights,
        "robots": [{"name": "r", "pose": {"translation": [offset[0], offset[1], 0.0]},
                    "devices": [{"device": "Camera", "name": "cam", **cam}]}]}), precision)
    cos = -(rays(cam)[0] @ np.array([-math.cos(yaw), -math.sin(yaw), 0.0]))
    assert cos.min() < 0.05 if yaw else cos.min() > 0.75      # (grazing at the turned wall's edge)
    np.testing.assert_array_equal(rgb(img), expected_bytes(0.5 * d * (0.3 + 0.8 * cos)[..., None]))


def test_background_and_far_plane():
    """Webots clears a camera's HDR buffer with the sky colour reverse tone mapped
    (WbBackground::applyColorToWren: -ln(1.000000001 - c^2.2)), so at exposure 1 the background
    pixels are the sky colour's bytes (51, 102, 255 here; they were the tone map of the colour
    itself, 117, 161, 207); at another exposure they are the resolve of that radiance."""
    cam = {"width": 4, "height": 3, "field_of_view": 0.5, "far": 1.0}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 1.0}
    sky = {"sky_color": [0.2, 0.4, 1.0]}
    _, img = shoot(world(cam, [WALL], [amb], background=sky))
    np.testing.assert_array_equal(rgb(img), np.broadcast_to([51, 102, 255], (3, 4, 3)))
    hdr = -np.log(1.000000001 - np.array([0.2, 0.4, 1.0]) ** 2.2)
    _, img = shoot(world({**cam, "exposure": 0.5}, [WALL], [amb], background=sky))
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(hdr, 0.5), (3, 4, 3)))
    assert expected_bytes(hdr, 0.5).tolist() == [37, 76, 255]
    _, img = shoot(world({**cam, "far": 0.0}, [WALL], [amb], background={"sky_color": [0.2, 0.4, 1.0]}))
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(ALBEDO), (3, 4, 3)))


def test_texture_texels_are_linearised_and_multiplied_by_the_base_colour(tmp_path):
    from PIL import Image
    Image.new("RGB", (4, 4), (200, 100, 30)).save(tmp_path / "t.png")
    floor = {"name": "wall", "pose": {"translation": [1.0, 0, 0], "rotation": [0, 1, 0, -math.pi / 2]},
             "geometry": {"type": "plane", "size": [3, 3]},
             "appearance": {"base_color": [0.5, 1.0, 1.0], "texture": "t.png"}}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 1.0}
    sim, img = shoot(world({"width": 3, "height": 3, "field_of_view": 0.4}, [floor], [amb]), base_dir=tmp_path)
    c = np.array([200, 100, 30]) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    np.testing.assert_array_equal(rgb(img), np.broadcast_to(expected_bytes(lin * [0.5, 1.0, 1.0]), (3, 3, 3)))
    assert sim.counters["texture_lookups"] == 9


def test_anti_aliasing_averages_four_rays_per_pixel():
    # a wall edge at y = 0 seen by a 2-pixel-wide camera: each pixel's 2x2 rays split 2 on / 2 off the
    # wall; the pixel is the tone-mapped mean radiance of its four rays
    half = {"name": "half", "pose": {"translation": [2.0, -2.5, 0.0]}, "geometry": {"type": "box", "size": [0.1, 5, 20]},
            "appearance": {"base_color": [1, 1, 1]}}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 1.0}
    cam = {"width": 3, "height": 1, "field_of_view": 0.3, "anti_aliasing": True}
    sim, img = shoot(world(cam, [half], [amb]))
    d = rays(cam, imaging.SAMPLES_2X2)                 # (4, 1, 3, 3)
    on = d[..., 1] < 0                                  # right of the edge: the wall (ambient 1), else black
    L = on.mean(axis=0)[0]                              # (3,) mean radiance per pixel (albedo 1)
    np.testing.assert_array_equal(rgb(img)[0], np.repeat(expected_bytes(L)[:, None], 3, axis=1))
    assert list(L) == [0.0, 0.5, 1.0]
    assert sim.counters["rays_camera"] == 4 * 3


def test_exposure_noise_and_determinism():
    cam = {"width": 40, "height": 30, "field_of_view": 0.5}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.3}
    grey = {**WALL, "appearance": {"base_color": [1, 1, 1]}}
    sim, img = shoot(world({**cam, "exposure": 2.0}, [grey], [amb]))
    assert np.all(rgb(img) == expected_bytes(0.3, exposure=2.0))
    sim.device("r/cam").set_exposure(0.5)
    sim.run(1)
    assert np.all(rgb(sim.device("r/cam").image) == expected_bytes(0.3, exposure=0.5))
    a = shoot(world({**cam, "noise": 0.05}, [grey], [amb]), steps=2)[1]
    b = shoot(world({**cam, "noise": 0.05}, [grey], [amb]), steps=2)[1]
    assert a.tobytes() == b.tobytes()                   # same seed, same bytes
    clean = expected_bytes(0.3)
    err = rgb(a) - clean
    assert abs(err.std() - 0.05 * 255) < 0.6 and abs(err.mean()) < 0.6
    assert np.all(a[:, :, 3] == 255)


def test_lazy_rays_and_the_same_pixels_as_a_range_finder():
    # a spherical camera and a spherical range finder at the same pose see the same pixels hit
    ball = {"name": "ball", "pose": {"translation": [1.0, 0.3, 0.1]}, "geometry": {"type": "sphere", "radius": 0.3},
            "appearance": {"base_color": [1, 1, 1]}}
    amb = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 1.0}
    geo = {"width": 32, "height": 24, "field_of_view": 2.0, "projection": "spherical"}
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 16}, "solids": [ball], "lights": [amb],
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **geo},
                                             {"device": "RangeFinder", "name": "rf", **geo, "max_range": 50}]}]})
    sim = Simulation(w)
    sim.run(3)
    assert sim.counters["rays_camera"] == 0 and sim.counters["engine_rays"] == 0
    sim.device("r/cam").enable(16)
    sim.device("r/rf").enable(16)
    sim.run(1)
    seen = np.isfinite(sim.device("r/rf").range_image)
    white = rgb(sim.device("r/cam").image)[..., 0] == expected_bytes(1.0)
    np.testing.assert_array_equal(seen, white)
    assert 50 < seen.sum() < 32 * 24
    assert sim.counters["rays_camera"] == 32 * 24


def test_topics_are_bgra8_images_and_a_camera_info():
    cam = {"width": 8, "height": 6, "field_of_view": 0.9}
    sim = Simulation(world(cam, [WALL], [{"type": "PointLight", "location": [1, 0, 0]}]))
    core = Core(sim)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/cam/image"] == msgs.IMAGE and types["/r/cam/camera_info"] == msgs.CAMERA_INFO
    sim.device("r/cam").enable(16)
    sim.step()
    ctl = core.topics.controls["r/cam"]
    img = msgs.validate(msgs.IMAGE, core.topics.build(ctl, "image", sim.time_ms))
    assert (img.encoding, img.width, img.height, img.step) == ("bgra8", 8, 6, 32)
    assert img.data == sim.device("r/cam").image.tobytes()
    assert core.topics.reading(ctl) == {"image": img.data}
    info = msgs.validate(msgs.CAMERA_INFO, core.topics.build(ctl, "camera_info", sim.time_ms))
    assert np.frombuffer(info.k, "<f8")[0] == pytest.approx(4.0 / math.tan(0.45))


def test_fields_are_checked():
    with pytest.raises(ValueError, match="planar camera's field_of_view must be < pi"):
        world({"field_of_view": 3.5})
    with pytest.raises(ValueError, match="less than or equal to 1"):
        world({"noise": 2.0})


def test_python_api_through_a_server(tmp_path):
    import yaml
    from _inproc import inproc_server

    from sensorium.client import wb
    from sensorium.client.webots.controller import Camera, Robot
    w = world({"width": 6, "height": 4, "field_of_view": 0.8, "exposure": 1.5}, [WALL],
              [{"type": "PointLight", "location": [1.0, 0.0, 0.0], "attenuation": [0, 0, 1]}])
    path = tmp_path / "cam.yaml"
    path.write_text(yaml.safe_dump(w.model_dump(mode="json", exclude_defaults=True)))
    with inproc_server(heartbeat_ms=5000, world=path) as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/r")
        try:
            robot = Robot()
            cam = robot.getDevice("cam")
            assert isinstance(cam, Camera)
            assert (cam.getWidth(), cam.getHeight(), cam.getExposure(), cam.getNear()) == (6, 4, 1.5, 0.01)
            assert cam.getFov() == cam.getMinFov() == cam.getMaxFov() == pytest.approx(0.8)
            assert cam.getImage() is None                                 # disabled: NULL (Webots)
            cam.enable(16)
            robot.step(16)
            img = cam.getImage()
            assert img == core.sim.device("r/cam").image.tobytes() and len(img) == 6 * 4 * 4
            r, g, b = Camera.imageGetRed(img, 6, 5, 3), Camera.imageGetGreen(img, 6, 5, 3), Camera.imageGetBlue(img, 6, 5, 3)
            assert (r, g, b) == tuple(core.sim.device("r/cam").image[3, 5, [2, 1, 0]])
            assert Camera.imageGetGray(img, 6, 5, 3) == (r + g + b) / 3
            assert wb.wb_camera_image_get_gray(img, 6, 5, 3) == (r + g + b) // 3
            arr = cam.getImageArray()
            assert len(arr) == 6 and len(arr[0]) == 4 and arr[5][3] == [r, g, b]      # [x][y]
            png = tmp_path / "cam.png"
            assert cam.saveImage(str(png), 100) == 0
            from PIL import Image
            np.testing.assert_array_equal(np.asarray(Image.open(png)), core.sim.device("r/cam").image[:, :, [2, 1, 0]])
            assert cam.saveImage(str(tmp_path / "x.gif"), 100) == -1
            cam.setExposure(0.25)
            assert core.sim.device("r/cam").exposure == 0.25 and cam.getExposure() == 0.25
            robot.step(16)
            assert cam.getImage() != img
        finally:
            wb.wb_robot_cleanup()
            Robot.created = None
