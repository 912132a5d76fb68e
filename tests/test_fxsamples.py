"""Webots' camera_motion_blur and camera_noise_mask samples on a stand-in world of ours
(tests/data/fxsamples/camera_fx.wbt: the samples' poses and sizes, our own text) driven by the calls
their controller (``camera``) makes: enable at the basic time step (32 ms), wheels at -4/+4 rad/s while no
blob is in the image's centre, stop 20 steps then turn 20 more on a blob. Each image is checked against
a twin camera without the effect in the same place: the blur's blend sequence at the sample's period
and motionBlur 500, the mask's alpha blend of a noise PNG of ours."""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from PIL import Image

from sensorium.server.devices.noise import device_rng
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "fxsamples"
TESTS_C = Path(__file__).parent / "c"
REPO = Path(__file__).resolve().parent.parent
STEP = 32
SPEED = 4.0
W_BLUR = 0.005 ** (STEP / 500)          # motion_blur.frag's weight at the sample's period and motionBlur


def to_byte(x: np.ndarray) -> np.ndarray:
    return np.floor(255.0 * np.asarray(x) + 0.5).astype(np.int64)


def resolved(L: np.ndarray) -> np.ndarray:
    """Webots' HDR resolve and byte of a radiance (exposure 1)."""
    return to_byte((1.0 - np.exp(-np.maximum(L, 0.0))) ** (1.0 / 2.2))


def rgb(image: np.ndarray) -> np.ndarray:
    return image[:, :, [2, 1, 0]].astype(np.int64)


def blob(image: np.ndarray) -> str | None:
    """camera.c's test: the sums of R, G, B over columns [w/3, 2w/3) and rows [h/2, 3h/4); a colour whose
    sum is over three times each other one is a blob."""
    h, w = image.shape[:2]
    r, g, b = rgb(image)[h // 2:3 * h // 4, w // 3:2 * w // 3].sum(axis=(0, 1))
    for name, x, y, z in (("red", r, g, b), ("green", g, r, b), ("blue", b, r, g)):
        if x > 3 * y and x > 3 * z:
            return name
    return None


def noise_mask_world(folder: Path) -> np.ndarray:
    """FOLDER/camera_fx.wbt: the stand-in as camera_noise_mask has it (400 x 300, no blur,
    ``noiseMaskUrl "textures/noise_mask.png"``) and that PNG: a 400 x 300 RGBA noise of ours (alpha below
    0.5), returned as (300, 400, 4) bytes."""
    text = (DATA / "camera_fx.wbt").read_text()
    text = text.replace("width 80 height 60 antiAliasing TRUE motionBlur 500",
                        'width 400 height 300 antiAliasing TRUE noiseMaskUrl "textures/noise_mask.png"')
    text = text.replace("width 80 height 60 antiAliasing TRUE }", "width 400 height 300 antiAliasing TRUE }")
    (folder / "textures").mkdir()
    (folder / "camera_fx.wbt").write_text(text)
    noise = np.random.default_rng(7)
    texels = np.concatenate([noise.integers(0, 256, (300, 400, 3)), noise.integers(0, 128, (300, 400, 1))], axis=2)
    Image.fromarray(texels.astype(np.uint8), "RGBA").save(folder / "textures" / "noise_mask.png")
    return texels


def camera_sample(sim: Simulation, name: str, steps: int, each=None) -> list[tuple[int, str]]:
    """camera.c's loop on the camera ``name``: its prints as (ms, colour)."""
    robot = sim.robot("MyBot")
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    cam = sim.device(f"MyBot/{name}")
    cam.enable(STEP)
    pause, prints = 0, []
    for k in range(1, steps + 1):
        if each is not None:
            each(k)
        sim.run(1)
        if each is not None:
            each(-k)
        pause = max(pause - 1, 0)
        speeds = (-SPEED, SPEED)
        if pause > 640 // STEP:
            speeds = (0.0, 0.0)
        elif pause == 0:
            found = blob(cam.image)
            if found is not None:
                prints.append((k * STEP, found))
                speeds, pause = (0.0, 0.0), 1280 // STEP
        left.set_velocity(speeds[0])
        right.set_velocity(speeds[1])
    return prints


def test_camera_motion_blur_sample_images_follow_the_blend_sequence() -> None:
    """The sample's camera (80 x 60, antiAliasing, motionBlur 500) and a twin without the blur, at the
    same place on the robot, for 10 s of camera.c's turning: the first image is the twin's (R = L), then each
    image's mixed radiance is ``R ← L(1 − w) + R w`` with w = 0.005^(32/500) = 0.7124 and its bytes are
    R's resolve, and the radiance the blur was given, ``(R − w R_prev)/(1 − w)``, resolves to the twin's
    bytes (at most one step: float64 round trip; >99% exact). The controller finds the same blobs on
    the blurred camera as on the twin, in the same order, each a step or more later (the blur lags)."""
    loaded = load_world(DATA / "camera_fx.wbt")
    assert loaded.world.robots[0].devices  # both cameras loaded
    sim = Simulation(loaded)
    cam, twin = sim.device("MyBot/camera"), sim.device("MyBot/plain")
    twin.enable(STEP)
    held: dict[str, np.ndarray] = {}
    exact = []

    def check(k: int) -> None:
        if k > 0:
            held["R"] = None if cam._blurred is None else cam._blurred.copy()
            return
        R = cam._blurred.reshape(60, 80, 3)
        assert np.array_equal(rgb(cam.image), resolved(R)), k
        if held["R"] is None:               # the first image: itself
            np.testing.assert_array_equal(cam.image, twin.image)
            return
        L = (R - W_BLUR * held["R"].reshape(60, 80, 3)) / (1.0 - W_BLUR)
        diff = np.abs(resolved(L) - rgb(twin.image))
        assert diff.max() <= 1, k
        exact.append(float(np.mean(diff == 0)))

    blurred = camera_sample(sim, "camera", 10000 // STEP, check)
    assert min(exact) > 0.99, min(exact)
    plain = camera_sample(Simulation(load_world(DATA / "camera_fx.wbt")), "plain", 10000 // STEP)
    assert len(blurred) == len(plain) > 3
    assert [c for _, c in blurred] == [c for _, c in plain]
    assert all(tb > tp for (tb, _), (tp, _) in zip(blurred, plain))


def test_camera_noise_mask_sample_images_are_the_twin_mixed_with_the_mask(tmp_path: Path) -> None:
    """The sample's camera with its 400 x 300 image and ``noiseMaskUrl "textures/noise_mask.png"`` (a
    400 x 300 RGBA noise of ours, alpha up to 0.5), no blur, and the twin: the mask is the image's size,
    so it is read one texel per pixel shifted by (400 ox, 300 oy) texels, the camera's stream's two
    uniform draws per image (bilinear between the two texels either side); each image is the twin's
    ``c(1 − a) + m a`` of that read (at most one step: the bilinear sums' order; >90% exact), and the
    offsets differ image to image (the mask flickers)."""
    texels = noise_mask_world(tmp_path)
    loaded = load_world(tmp_path / "camera_fx.wbt")
    assert not [w for w in loaded.warnings if "noiseMask" in w or "noise mask" in w], loaded.warnings
    sim = Simulation(loaded)
    cam, twin = sim.device("MyBot/camera"), sim.device("MyBot/plain")
    twin.enable(STEP)
    rng = device_rng(int(loaded.world.world_info.random_seed), "MyBot/camera")
    m = texels / 255.0
    offsets = []

    def check(k: int) -> None:
        if k > 0:
            return
        ox, oy = rng.random(2)
        offsets.append((ox, oy))
        x, y = np.arange(400) + 400 * ox, np.arange(300) + 300 * oy       # texel k's centre at k
        x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
        fx, fy = (x - x0)[None, :, None], (y - y0)[:, None, None]
        c00, c01 = m[np.ix_(y0 % 300, x0 % 400)], m[np.ix_(y0 % 300, (x0 + 1) % 400)]
        c10, c11 = m[np.ix_((y0 + 1) % 300, x0 % 400)], m[np.ix_((y0 + 1) % 300, (x0 + 1) % 400)]
        read = (c00 * (1 - fx) + c01 * fx) * (1 - fy) + (c10 * (1 - fx) + c11 * fx) * fy
        a = read[..., 3:]
        want = to_byte(np.clip(rgb(twin.image) / 255.0 * (1 - a) + read[..., :3] * a, 0, 1))
        diff = np.abs(rgb(cam.image) - want)
        assert diff.max() <= 1, k
        assert np.mean(diff == 0) > 0.9, k
        assert not np.array_equal(rgb(cam.image), rgb(twin.image))

    camera_sample(sim, "camera", 4, check)
    assert len(set(offsets)) == 4


@pytest.fixture(scope="module")
def clib(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Our libController built once for this file: (its build folder, the libraries to link)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path_factory.mktemp("cbuild")
    make = ["make", "-s", "-C", str(REPO / "sensorium" / "client" / "c")]
    done = subprocess.run([*make, f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return build, subprocess.run([*make, "libs"], capture_output=True, text=True, timeout=60).stdout.split()


@pytest.mark.slow
@pytest.mark.parametrize(("sample", "until"), [("camera_motion_blur", 10000), ("camera_noise_mask", 4000)])
def test_the_camera_controller_runs_on_the_stand_ins(tmp_path: Path, clib, sample: str, until: int) -> None:
    """The sample's controller (Webots' camera.c from $WEBOTS_HOME's projects/samples/devices, unchanged;
    without it tests/c/camera_blobs.c making its calls) under ``sensorium run`` on each stand-in
    (10 s with the blur, 4 s with the mask): it finds the blobs the in-process loop above finds on that camera, in that order
    (and, ours printing the time, at those times), and saves each image to $HOME."""
    home = os.environ.get("WEBOTS_HOME")
    webots = Path(home or "/nonexistent") / "projects" / "samples" / "devices" / "controllers" / "camera" / "camera.c"
    source = webots if webots.is_file() else TESTS_C / "camera_blobs.c"
    folder = tmp_path / "controllers" / "camera"
    folder.mkdir(parents=True)
    shutil.copy(source, folder / "camera.c")
    build, libs = clib
    done = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(folder / "camera.c"), "-o",
                           str(folder / "camera"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "camera_fx.wbt"
    if sample == "camera_noise_mask":
        noise_mask_world(world.parent)
    else:
        shutil.copy(DATA / "camera_fx.wbt", world)
    expected = camera_sample(Simulation(load_world(world)), "camera", until // STEP)
    world.write_text(world.read_text().replace('controller "<extern>"', 'controller "camera"'))
    run = subprocess.run(sensorium("run", str(world), "--until", str(until), "--rpc", "tcp://127.0.0.1:0",
                                   "--pub", "tcp://127.0.0.1:0"),
                         env=child_env({"HOME": str(tmp_path)}), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    found = [re.search(r"(red|green|blue)", ln) for ln in run.stdout.splitlines() if "blob" in ln]
    assert [m.group(1) for m in found if m] == [c for _, c in expected]
    if source != webots:
        times = [int(ln.split()[-1]) for ln in run.stdout.splitlines() if " blob " in f" {ln}"]
        assert times == [t for t, _ in expected]
    assert {p.name for p in tmp_path.glob("*_blob.png")} == {f"{c}_blob.png" for _, c in expected}
