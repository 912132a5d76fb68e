"""A Camera's motion blur (Webots' ``motionBlur``) and noise mask (``noiseMaskUrl``) against closed
forms: a static scene is a fixed point of the blur, a light switched on and off gives the blend
sequence ``R ← L(1 − w) + R w`` with ``w = 0.005^(period/motionBlur)``, a uniform mask mixes its colour
over every pixel by its alpha, a checker mask is read bilinearly at the offsets the camera's stream
draws; a bad mask file is one problem naming the field. A RangeFinder's motion blur: a wall that
jumps from d1 to d2 gives the blend sequence on the depths, an infinite value (new or last) is not
mixed, the noise is drawn after the blur and never fed back. The batched simulation's copies with
either effect: tests/test_batched_camera.py and test_batched_depth.py."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sensorium.schemas import world as wm
from sensorium.server.devices.noise import device_rng
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
        "appearance": {"base_color": [0.8, 0.5, 0.2]}}
ALBEDO = np.array([0.8, 0.5, 0.2])
SUN = {"type": "DirectionalLight", "direction": [1.0, 0.0, 0.0], "intensity": 1.5}   # head-on: cos 1 on the wall


def world_dict(cam: dict, lights=(SUN,)) -> dict:
    return {"world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [WALL], "lights": list(lights),
            "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", "width": 6, "height": 4,
                                                  "field_of_view": 0.8, **cam}]}]}


def sim_of(cam: dict, base_dir: Path | None = None, lights=(SUN,)) -> Simulation:
    d = world_dict(cam, lights)
    if base_dir is None:
        return Simulation(wm.World.model_validate(d))
    return Simulation(parse_world(d, base_dir=base_dir))


def to_byte(x: np.ndarray) -> np.ndarray:
    return np.floor(255.0 * np.asarray(x) + 0.5).astype(np.int64)


def resolved(L: np.ndarray) -> np.ndarray:
    """Webots' HDR resolve and byte of a radiance (exposure 1)."""
    return to_byte((1.0 - np.exp(-np.asarray(L))) ** (1.0 / 2.2))


def rgb(image: np.ndarray) -> np.ndarray:
    return image[:, :, [2, 1, 0]].astype(np.int64)


# ------------------------------------------------------------------------------------ motion blur

def test_a_static_scene_is_a_fixed_point_of_the_motion_blur():
    plain, blurred = sim_of({}), sim_of({"motion_blur": 300.0})
    for s in (plain, blurred):
        s.device("r/cam").enable(16)
    for _ in range(12):
        plain.run(1)
        blurred.run(1)
        a, b = plain.device("r/cam").image, blurred.device("r/cam").image
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(rgb(b), np.broadcast_to(resolved(ALBEDO * 1.5), (4, 6, 3)))


def test_a_light_switched_on_and_off_gives_the_blend_sequence():
    # the wall lit head-on (L = albedo · 1.5) or black (L = 0), switched at each image; every image is
    # R_n = L_n (1 − w) + R_{n−1} w, R_0 = L_0, with w = 0.005^(16 / 100)
    sim = sim_of({"motion_blur": 100.0})
    cam = sim.device("r/cam")
    cam.enable(16)
    on = sim.scene.top_lights()[0]
    off = on.model_copy(update={"on": False})
    w = 0.005 ** (16 / 100.0)
    lit = ALBEDO * 1.5
    R = None
    pattern = [1, 0, 0, 1, 1, 1, 0, 1, 0, 0, 1, 1]
    for k, state in enumerate(pattern):
        sim.scene.set_top_light(0, on if state else off)
        sim.run(1)
        L = lit if state else np.zeros(3)
        R = L if R is None else L * (1.0 - w) + R * w
        got = rgb(cam.image)
        assert np.all(got == got[0, 0]), k               # uniform: the blur is per pixel
        np.testing.assert_array_equal(got[0, 0], resolved(R), err_msg=f"image {k}")
    assert len({tuple(resolved(x)) for x in (lit, np.zeros(3))}) == 2


def test_motion_blur_reaches_99_5_percent_after_motion_blur_ms():
    # Webots' definition: 160 ms at a 16 ms period is 10 images; a step from black to lit is then at
    # 1 − w^10 = 0.995 of the lit radiance
    sim = sim_of({"motion_blur": 160.0}, lights=[{**SUN, "intensity": 0.2}])
    cam = sim.device("r/cam")
    cam.enable(16)
    on = sim.scene.top_lights()[0]
    sim.scene.set_top_light(0, on.model_copy(update={"on": False}))
    sim.run(1)
    sim.scene.set_top_light(0, on)
    sim.run(10)
    from sensorium.server.devices.shading import motion_blur_weight

    w = motion_blur_weight(16, 160.0)
    assert abs(w ** 10 - 0.005) < 1e-15
    R = np.zeros(3)
    for _ in range(10):
        R = ALBEDO * 0.2 * (1.0 - w) + R * w
    np.testing.assert_allclose(R, ALBEDO * 0.2 * 0.995, rtol=1e-12)
    np.testing.assert_array_equal(rgb(cam.image)[0, 0], resolved(R))


def test_motion_blur_weight_follows_the_sampling_period():
    # the same scene sampled every 32 ms: w = 0.005^(32/100)
    sim = sim_of({"motion_blur": 100.0})
    cam = sim.device("r/cam")
    cam.enable(32)
    on = sim.scene.top_lights()[0]
    sim.run(2)
    sim.scene.set_top_light(0, on.model_copy(update={"on": False}))
    sim.run(2)
    w = 0.005 ** (32 / 100.0)
    np.testing.assert_array_equal(rgb(cam.image)[0, 0], resolved(ALBEDO * 1.5 * w))


# ------------------------------------------------------------------------------------ noise mask

def _mask(tmp_path: Path, name: str, texels: np.ndarray) -> str:
    mode = "RGBA" if texels.shape[-1] == 4 else "RGB"
    Image.fromarray(texels.astype(np.uint8), mode).save(tmp_path / name)
    return name


def test_a_uniform_noise_mask_mixes_its_colour_over_every_pixel_by_its_alpha(tmp_path):
    plain = sim_of({})
    plain.device("r/cam").enable(16)
    plain.run(1)
    c = rgb(plain.device("r/cam").image)
    assert np.all(c == resolved(ALBEDO * 1.5))
    texel = np.array([30, 200, 90, 100])
    url = _mask(tmp_path, "mask.png", np.broadcast_to(texel, (8, 8, 4)))
    sim = sim_of({"noise_mask_url": url}, tmp_path)
    cam = sim.device("r/cam")
    cam.enable(16)
    a = texel[3] / 255.0
    want = to_byte((c / 255.0) * (1.0 - a) + (texel[:3] / 255.0) * a)
    for _ in range(3):                    # every image (each at its own offset): the same uniform mix
        sim.run(1)
        np.testing.assert_array_equal(rgb(cam.image), want)
        assert np.all(cam.image[:, :, 3] == 255)
    assert not np.array_equal(want, c)
    # an opaque mask (an RGB file: alpha 1) replaces the image; a clear one leaves it
    for texels, expect in ((np.broadcast_to([30, 200, 90], (4, 4, 3)), np.broadcast_to([30, 200, 90], c.shape)),
                           (np.broadcast_to([30, 200, 90, 0], (4, 4, 4)), c)):
        url = _mask(tmp_path, f"m{texels.shape[-1]}.png", np.array(texels))
        sim = sim_of({"noise_mask_url": url}, tmp_path)
        sim.device("r/cam").enable(16)
        sim.run(1)
        np.testing.assert_array_equal(rgb(sim.device("r/cam").image), expect)


def test_a_one_texel_mask_is_a_uniform_mix_at_every_offset(tmp_path):
    # the smallest mask: every bilinear corner is the one texel, so each image is the uniform mix whatever its offset
    plain = sim_of({})
    plain.device("r/cam").enable(16)
    plain.run(1)
    c = rgb(plain.device("r/cam").image)
    texel = np.array([250, 10, 120, 77])
    sim = sim_of({"noise_mask_url": _mask(tmp_path, "one.png", texel.reshape(1, 1, 4))}, tmp_path)
    sim.device("r/cam").enable(16)
    a = texel[3] / 255.0
    for _ in range(4):
        sim.run(1)
        np.testing.assert_array_equal(rgb(sim.device("r/cam").image), to_byte((c / 255.0) * (1.0 - a)
                                                                                + (texel[:3] / 255.0) * a))


def test_a_checker_mask_is_read_bilinearly_at_the_offsets_the_camera_stream_draws(tmp_path):
    # a 2 x 2 mask (smaller than the 6 x 4 image: it spans the image's height once, square texels
    # across, factor (1, 4/6)), alpha 255 so the image is the mask; its offsets are the camera's own
    # stream's first draws (no colour noise draws before them)
    texels = np.array([[[255, 0, 0, 255], [0, 0, 255, 255]], [[0, 255, 0, 255], [255, 255, 255, 255]]])
    url = _mask(tmp_path, "checker.png", texels)
    sim = sim_of({"noise_mask_url": url}, tmp_path)
    cam = sim.device("r/cam")
    cam.enable(16)
    rng = device_rng(5, "r/cam")
    colours = texels[..., :3] / 255.0
    seen = []
    for _ in range(3):
        sim.run(1)
        ox, oy = rng.random(2)
        fx, fy = 1.0, 4 / 6
        want = np.zeros((4, 6, 3))
        for j in range(4):
            for i in range(6):
                x = ((i + 0.5) / 6 + ox) * fx * 2 - 0.5
                y = ((j + 0.5) / 4 + oy) * fy * 2 - 0.5
                x0, y0 = int(np.floor(x)), int(np.floor(y))
                tx, ty = x - x0, y - y0
                c = sum(colours[(y0 + dy) % 2, (x0 + dx) % 2] * (tx if dx else 1 - tx) * (ty if dy else 1 - ty)
                        for dx in (0, 1) for dy in (0, 1))
                want[j, i] = c
        got = rgb(cam.image)
        assert np.abs(got - to_byte(want)).max() <= 1      # the bilinear sums' order: at most one step
        assert np.mean(got == to_byte(want)) > 0.9
        seen.append(got)
    assert not np.array_equal(seen[0], seen[1])            # a new offset per image: the noise flickers
    again = sim_of({"noise_mask_url": url}, tmp_path)      # the same seed: the same images
    again.device("r/cam").enable(16)
    again.run(1)
    np.testing.assert_array_equal(rgb(again.device("r/cam").image), seen[0])


def test_noise_mask_factor_is_webots():
    from sensorium.server.devices.shading import noise_mask_factor

    assert noise_mask_factor(64, 48, 128, 128) == (0.5, 0.375)       # larger: one texel per pixel
    assert noise_mask_factor(64, 48, 32, 32) == (1.0, 0.75)          # smaller: the height once, square across
    assert noise_mask_factor(48, 64, 32, 32) == (0.75, 1.0)
    assert noise_mask_factor(64, 48, 100, 40) == (64 / 48, 1.0)      # only its height short


def test_a_bad_noise_mask_file_is_one_problem_naming_the_field(tmp_path):
    (tmp_path / "notimage.png").write_text("hello")
    (tmp_path / "sub").mkdir()
    cases = {"missing.png": "not found", "notimage.png": "is not a PNG or JPEG image",
             "../outside.png": "leaves the world's folder"}
    for url, why in cases.items():
        with pytest.raises(WorldError) as exc:
            parse_world(world_dict({"noise_mask_url": url}), base_dir=tmp_path / ("sub" if url.startswith("..") else ""))
        (problem,) = exc.value.problems
        assert problem.path == "robots[0].devices[0].noise_mask_url" and why in problem.message, (url, problem)
        assert "\n" not in str(problem)
    with pytest.raises(ValueError, match="noise_mask_url: Webots applies a noise mask to planar cameras only"):
        wm.World.model_validate(world_dict({"noise_mask_url": "m.png", "projection": "spherical"}))
    with pytest.raises(ValueError, match="greater than or equal to 0"):
        wm.World.model_validate(world_dict({"motion_blur": -1}))


@pytest.mark.slow
def test_the_cli_names_a_bad_noise_mask_in_one_line(tmp_path):
    import subprocess
    import sys

    import yaml

    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump(world_dict({"noise_mask_url": "nope.png"})))
    out = subprocess.run([sys.executable, "-m", "sensorium", "validate", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode != 0
    lines = [ln for ln in (out.stdout + out.stderr).splitlines() if "noise_mask_url" in ln]
    assert len(lines) == 1 and "nope.png" in lines[0] and "not found" in lines[0], out
    assert "Traceback" not in out.stderr


def test_a_wbt_camera_keeps_motion_blur_and_its_noise_mask(tmp_path):
    from sensorium.server.world.loader import load_world

    Image.new("RGBA", (4, 4), (10, 20, 30, 40)).save(tmp_path / "noise.png")
    (tmp_path / "w.wbt").write_text(
        "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\nViewpoint { }\n"
        'Robot { name "r" children [ Camera { name "cam" motionBlur 200 noiseMaskUrl "noise.png" } ] }\n'
        'Robot { name "s" children [ Camera { name "cam" spherical TRUE noiseMaskUrl "noise.png" } ] }\n')
    loaded = load_world(tmp_path / "w.wbt")
    cams = [r.devices[0] for r in loaded.world.robots]
    assert (cams[0].motion_blur, cams[0].noise_mask_url) == (200.0, "noise.png")
    assert cams[1].noise_mask_url == ""
    assert not [w for w in loaded.warnings if "not rendered here" in w and ("motionBlur" in w or "noiseMask" in w)]
    assert [w for w in loaded.warnings if "noise mask to planar cameras only" in w]
    # `sensorium convert` writing the world elsewhere names the mask relative to where it is written
    from sensorium.server.world.wbt.emit import converted_world

    (tmp_path / "out").mkdir()
    data = converted_world(tmp_path / "w.wbt", tmp_path / "out")
    assert data["robots"][0]["devices"][0]["noise_mask_url"] == "../noise.png"


# ------------------------------------------------------------------ a range finder's motion blur

def ranging(rf: dict, twin: dict | None = None) -> Simulation:
    """A robot at the origin whose planar range finder "rf" (5 x 3 pixels, max_range 5) faces the
    wall's near face, the plane x = 1.95; ``twin``: a second one, "twin", beside it."""
    devs = [{"device": "RangeFinder", "name": "rf", "width": 5, "height": 3, "field_of_view": 0.6, "max_range": 5.0,
             **rf}]
    if twin is not None:
        devs.append({**devs[0], "name": "twin", **twin})
    return Simulation(wm.World.model_validate(
        {"world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [WALL],
         "robots": [{"name": "r", "devices": devs}]}))


def test_a_range_finder_seeing_a_wall_jump_gives_the_blend_sequence():
    # planar depth: every pixel reads the wall's distance, 1.95 m, then 1.2 m once the robot is put
    # 0.75 m nearer: B <- d2 (1 - w) + B w from B = d1, w = 0.005^(16/100) per 16 ms image
    sim = ranging({"motion_blur": 100.0})
    rf = sim.device("r/rf")
    rf.enable(16)
    sim.run(1)
    np.testing.assert_allclose(rf.range_image, 1.95, rtol=1e-6)          # the first image: itself
    sim.robot("r").set_pose([0.75, 0.0, 0.0])
    w = 0.005 ** (16 / 100)
    B = 1.95
    for k in range(12):
        sim.run(1)
        B = 1.2 * (1 - w) + B * w
        np.testing.assert_allclose(rf.range_image, np.full((3, 5), B), rtol=1e-6, err_msg=str(k))
    assert abs(B - 1.2) < 0.01 * 0.75                 # within 1% of the jump after 12 images (> 100 ms)
    # back: the sequence from where it stands towards d1
    sim.robot("r").set_pose([0.0, 0.0, 0.0])
    sim.run(1)
    np.testing.assert_allclose(rf.range_image, 1.95 * (1 - w) + B * w, rtol=1e-6)


def test_an_infinite_range_is_not_mixed_by_the_motion_blur():
    # a twin without blur gives the exact values; facing away (nothing within max_range: +inf) the
    # blurred image is +inf at once, and facing the wall again it is the wall's depth at once, bit for
    # bit the twin's (motion_blur.frag passes an infinite value, new or last, through as the new one)
    sim = ranging({"motion_blur": 500.0}, twin={"motion_blur": 0.0})
    rf, twin = sim.device("r/rf"), sim.device("r/twin")
    rf.enable(16)
    twin.enable(16)
    sim.run(3)
    assert rf.range_image.tobytes() == twin.range_image.tobytes()
    sim.robot("r").set_pose([0.75, 0.0, 0.0])
    sim.run(1)
    assert (rf.range_image > twin.range_image).all()          # blurred: between 1.95 and 1.2
    sim.robot("r").set_pose(rotation=[0, 0, 1, math.pi])
    sim.run(1)
    assert np.isposinf(rf.range_image).all() and np.isposinf(twin.range_image).all()
    sim.robot("r").set_pose(rotation=[0, 0, 1, 0.0])
    sim.run(1)
    assert rf.range_image.tobytes() == twin.range_image.tobytes()
    np.testing.assert_allclose(rf.range_image, 1.2, rtol=1e-6)


def test_the_range_noise_is_drawn_after_the_blur_and_not_fed_back():
    # a static wall with noise (sigma 0.02 x 5 m): the blurred values stay the wall's depth (a fixed
    # point), so each image is that depth plus the device's own stream's draws, as without the blur
    # (the same seed and device name); noise fed back into the blur would move them by ~0.1 m
    blurred, plain = ranging({"motion_blur": 300.0, "noise": 0.02}), ranging({"noise": 0.02})
    for s in (blurred, plain):
        s.device("r/rf").enable(16)
    rng = device_rng(5, "r/rf")
    for _ in range(6):
        blurred.run(1)
        plain.run(1)
        a, b = blurred.device("r/rf").range_image, plain.device("r/rf").range_image
        np.testing.assert_allclose(a, b, rtol=1e-6)
        np.testing.assert_allclose(a, 1.95 + 0.1 * rng.standard_normal(15).reshape(3, 5), rtol=1e-6)
    assert np.std(a) > 0.02


def test_a_wbt_range_finder_keeps_its_motion_blur(tmp_path):
    from sensorium.server.world.loader import load_world

    (tmp_path / "w.wbt").write_text(
        "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\nViewpoint { }\n"
        'Robot { name "r" children [ RangeFinder { name "rf" motionBlur 40 } ] }\n')
    loaded = load_world(tmp_path / "w.wbt")
    assert loaded.world.robots[0].devices[0].motion_blur == 40.0
    assert not [w for w in loaded.warnings if "motionBlur" in w]
    with pytest.raises(ValueError, match="greater than or equal to 0"):
        wm.World.model_validate({"robots": [{"name": "r", "devices": [{"device": "RangeFinder", "name": "rf",
                                                                        "motion_blur": -5}]}]})


@pytest.mark.parametrize("device", ["Camera", "RangeFinder"])
@pytest.mark.parametrize(("value", "words"), [
    ("nan", "column 71: number 'nan' is not finite"),
    ("1e999", "column 71: number '1e999' is out of range"),
    ("1e300", "the magnitude of 1e+300 exceeds the limit of 1e+09"),
    ("4.9e-324", "5e-324 is too close to 0 (use 0, or a magnitude of at least 1e-30)"),
    ("1e-310", "1e-310 is too close to 0"),
    ("TRUE", "motionBlur: expected one number, got True"),
])
def test_a_hostile_motion_blur_is_one_line_naming_the_file_and_line(tmp_path, device, value, words):
    # a denormal would make 0.005^(period/motionBlur) underflow silently, a huge one never change the image
    world = tmp_path / "w.wbt"
    world.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep 16 }}\nRobot {{ children [ {device:<11} {{ '
                     f'name "c" width 4 height 2 motionBlur {value} }} ] }}\n')
    with pytest.raises(WorldError) as info:
        load_world(world)
    line = str(info.value)
    assert line.startswith(f"{world}: line 3, column ") and words in line and "\n" not in line, line
