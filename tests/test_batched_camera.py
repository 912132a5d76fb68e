"""Cameras in the batched simulation (sensorium/server/sim/batched_camera.py): every copy's RGB
images bit-identical to the single Simulation with its seed (noise, exposure, anti-aliasing, fog,
textures, every light type, shadows, semi-transparent surfaces, a housed camera, the other robot in
view), closed-form pixels (lit, fogged, shadowed), copies blind to each other's robots, the vector
environment observing them, and the template's refusals (recognition: test_batched_recognition.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests._copies import check_sub_env, copies_and_singles, reseed_copy, steer_randomly, vector_beside_singles
from tests.test_batched_depth import scout_ahead_in_copy_0
from tests.test_gym_vector import _reset_both, _step_both

WORLD = Path(__file__).parent / "worlds" / "camera.yaml"
PERIODS = {"rover": {"eye": 32, "housed": 16, "pano": 48}, "scout": {"dome": 16}}
BOTH = ["fast", "exact"]


def _world(seed: int, base: Path, **update) -> LoadedWorld:
    lw = load_world(base / WORLD.name)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed}),
                                    **update})
    return LoadedWorld(world=w, source=lw.source, base_dir=base)


def _glass(seed: int, base: Path) -> LoadedWorld:
    """The camera world with a semi-transparent crate (0.4) and a semi-transparent scout (0.5)."""
    lw = _world(seed, base)
    w = lw.world
    crate = w.solids[2]
    glass = crate.model_copy(update={"appearance": crate.appearance.model_copy(update={"transparency": 0.4})})
    scout = w.robots[1]
    body = scout.body.model_copy(update={"appearance": scout.body.appearance.model_copy(update={"transparency": 0.5})})
    return LoadedWorld(world=w.model_copy(update={"solids": [*w.solids[:2], glass, *w.solids[3:]],
                                                  "robots": [w.robots[0], scout.model_copy(update={"body": body})]}),
                       source=lw.source, base_dir=base)


@pytest.mark.parametrize("glass", [False, True])
@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_captures_its_cameras_as_the_single_simulation(precision: str, glass: bool, texture_dir: Path):
    """Two robots driving among a textured floor, a crate, a wall and a lamp, under a point, a spot
    and a directional light (two casting shadows) in fog, with random per-copy wheel commands;
    cameras planar (noise, exposure, anti-aliasing), housed in a box of its own, cylindrical (noise,
    far) and spherical (anti-aliasing) at different periods; a reset of one copy with a new seed on
    the way; with ``glass`` the crate and the scout are semi-transparent (rays go on past them):
    after every basic step every image of every copy equals that of a Simulation built with that
    copy's seed, byte for byte (black before the first capture)."""
    seeds = [5, 6, 7]

    def make(seed: int) -> LoadedWorld:
        return (_glass if glass else _world)(seed, texture_dir)

    bs, sims = copies_and_singles(make, seeds, precision, PERIODS)
    through = []                                 # the casts of rays going on past a semi-transparent surface
    cast = bs.rays.cast

    def counted(origins, *args, **kwargs):
        if origins.strides[0] == 0:              # (from one camera's origin with per-ray limits: _layers)
            through.append(len(origins))
        return cast(origins, *args, **kwargs)

    bs.rays.cast = counted                       # type: ignore[method-assign]
    rng = np.random.default_rng(1)
    seen = {"black": 0, "sky": 0, "textured": 0}
    for step in range(70):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, PERIODS)
        if step == 40:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, make, 1, 42, precision, PERIODS)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    want = s.robot(robot).device(n).image
                    got = bs.image(bs.device(robot, n))[c]
                    assert got.dtype == np.uint8 and got.shape == want.shape
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n, np.abs(want.astype(int) - got).max())
                    seen["black"] += int(not got[..., :3].any())
            seen["textured"] += s.counters.get("texture_lookups", 0) > 0
        sky = np.array([204, 127, 76])        # BGR: the sky colour (0.8, 0.5, 0.3) x 255 at exposure 1 (Webots clears with it reverse tone mapped)
        dome = bs.image(bs.device("scout", "dome"))            # noiseless: the sky's exact bytes somewhere
        seen["sky"] += int((dome[..., :3] == sky).all(axis=-1).any())
    assert seen["black"] > 0 and seen["sky"] > 0 and seen["textured"] > 0
    assert (sum(through) > 1000) if glass else not through
    assert bs.camera.devices[1].own is not None            # "housed" meets its robot apart, blind to its box
    pano = bs.camera.devices[2].skip                       # some of pano's rays meet its own robot's mast
    assert isinstance(pano, np.ndarray) and 0 < (pano < 0).sum() < len(pano)
    # the noise is each copy's own: the same camera's images differ between copies
    eye = bs.image(bs.device("rover", "eye"))
    assert len({img.tobytes() for img in eye}) == len(seeds)


def _effects(seed: int, base: Path) -> LoadedWorld:
    """The camera world with motion blur and noise masks: the planar "eye" (noise, anti-aliasing)
    both, the housed one a mask only (no colour noise: its stream draws only the offsets), the
    cylindrical and spherical ones blur only (Webots masks planar cameras only); the mask a seeded
    5 x 7 RGBA image of varied alpha written next to the world (given unchecked, as the other
    textures here: each camera reads and checks it when built, cameras.noise_mask_planes)."""
    from PIL import Image

    texels = np.random.default_rng(11).integers(0, 256, (7, 5, 4), dtype=np.uint8)
    Image.fromarray(texels, "RGBA").save(base / "noise_mask.png")
    lw = _world(seed, base)
    fx = {"eye": {"motion_blur": 100.0, "noise_mask_url": "noise_mask.png"}, "housed": {"noise_mask_url": "noise_mask.png"},
          "pano": {"motion_blur": 60.0}, "dome": {"motion_blur": 30.0}}
    robots = [r.model_copy(update={"devices": [d.model_copy(update=fx[d.name]) for d in r.devices]})
              for r in lw.world.robots]
    w = wm.World.model_validate(lw.world.model_copy(update={"robots": robots}).model_dump())
    return LoadedWorld(world=w, source=lw.source, base_dir=base)     # unchecked: the cameras read the mask


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_blurs_and_masks_its_cameras_as_the_single_simulation(precision: str, texture_dir: Path):
    """The driving copies with motion blur and noise masks: each copy keeps its own last mixed
    radiance (its first image, and its first after a reset, itself), mixes at the weight of its own
    sampling period (copy 2's eye changes period on the way), and draws its mask's two offsets per
    image from its own camera stream after its image's colour noise: after every basic step every
    image of every copy equals its Simulation's, byte for byte."""
    seeds = [5, 6, 7]

    def make(seed: int) -> LoadedWorld:
        return _effects(seed, texture_dir)

    bs, sims = copies_and_singles(make, seeds, precision, PERIODS)
    rng = np.random.default_rng(4)
    for step in range(60):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, PERIODS)
        if step == 20:
            bs.enable(bs.device("rover", "eye"), 48, copies=[2])
            sims[2].robot("rover").device("eye").enable(48)
        if step == 35:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, make, 1, 42, precision, PERIODS)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    want = s.robot(robot).device(n).image
                    got = bs.image(bs.device(robot, n))[c]
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n, np.abs(want.astype(int) - got).max())
    # the effects are there: the same copy's images without them differ (mask offsets: every image)
    plain = Simulation(_world(5, texture_dir), precision=precision)
    masked = Simulation(make(5), precision=precision)
    for s in (plain, masked):
        s.robot("rover").device("housed").enable(16)
        s.step()
    assert plain.robot("rover").device("housed").image.tobytes() != masked.robot("rover").device("housed").image.tobytes()
    # each copy's mask offsets are its own stream's: the housed (noiseless) camera differs between copies
    housed = bs.image(bs.device("rover", "housed"))
    assert len({img.tobytes() for img in housed}) == len(seeds)


def test_the_rays_skipping_their_robot_never_meet_it(texture_dir: Path):
    """batched_depth.may_meet_parts (a camera's rays that may meet one of its robot's shapes; the
    others skip that robot in every copy's cast): 4,000 random rays from inside the rover's box (its
    cameras' places) that meet its body, cast in the body frame, are all kept, and most that do not
    are dropped."""
    from sensorium.server.raycast.engine import RayKind
    from sensorium.server.sim.batched_depth import may_meet_parts

    bs = BatchedSimulation(_world(0, texture_dir), 1)
    body = bs.rays.slot_body[0]
    rng = np.random.default_rng(3)
    for origin in ([0.07, 0.0, 0.1], [0.0, 0.0, 0.14], [0.09, 0.0, 0.08]):
        D = rng.normal(size=(4000, 3))
        D /= np.linalg.norm(D, axis=1)[:, None]
        O = np.broadcast_to(np.array(origin), D.shape)
        meets = np.isfinite(bs.rays.movers.cast_local(body, O, D, 0.0, np.inf, kind=RayKind.VISUAL).distance)
        kept = may_meet_parts(bs.world.robots[0], bs.loaded.base_dir, O, D, 0.0, np.inf)
        assert meets.any() and kept[meets].all(), origin
        assert (~kept[~meets]).mean() > 0.5, origin


def _facing(d: list[float], fog: bool) -> wm.World:
    """A robot without a body whose camera (11 x 5 pixels, 0.1 m up, exposure 1.3) faces a wide matte
    wall (the plane x = 2, albedo (0.6, 0.3, 0.15)) lit head-on by a directional light (intensity
    0.7, ambient 0.2); with fog: LINEAR, visibility 8 m, colour 0.5 grey."""
    dev = {"device": "Camera", "name": "cam", "pose": {"translation": [0.0, 0.0, 0.1]}, "width": 11, "height": 5,
           "field_of_view": 1.0, "exposure": 1.3}
    extra = {"fog": {"color": [0.5, 0.5, 0.5], "visibility_range": 8.0, "fog_type": "LINEAR"}} if fog else {}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False}, **extra,
        "lights": [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.7, "ambient_intensity": 0.2}],
        "solids": [{"name": "wall", "pose": {"translation": [2.5, 0.0, 0.0]},
                    "geometry": {"type": "box", "size": [1.0, 40.0, 40.0]},
                    "appearance": {"base_color": [0.6, 0.3, 0.15]}}],
        "robots": [{"name": "bot", "pose": {"translation": [2.0 - d[0], 0.0, 0.0]},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": [dev]}]})


@pytest.mark.parametrize("precision", BOTH)
def test_a_camera_facing_a_lit_matte_wall_reads_the_shading_models_value(precision: str):
    """Copy c stands d_c from the wall, facing it. The surface's radiance is albedo x (ambient +
    intensity x N.L) with N.L = 1, the same in every pixel without fog; with LINEAR fog the centre
    pixel (its ray along x, d_c long) is mixed with the fog's linear colour by w = (d_c/V)^2.2. The
    byte is floor(255 (1 - exp(-L exposure))^(1/2.2) + 1/2) (shading.py's model, written out here)."""
    d = [0.5, 1.0, 2.5, 4.0]
    albedo = np.array([0.6, 0.3, 0.15])
    L = albedo * (0.2 + 0.7 * 1.0)

    def byte(x: np.ndarray) -> np.ndarray:
        return np.floor(255.0 * (1.0 - np.exp(-x * 1.3)) ** (1.0 / 2.2) + 0.5)

    fog_lin = ((0.5 + 0.055) / 1.055) ** 2.4
    for fog in (False, True):
        bs = BatchedSimulation(LoadedWorld(world=_facing(d, fog), source="<test>", base_dir=Path.cwd()), len(d),
                               precision=precision)
        for c, dc in enumerate(d):
            bs.set_pose(c, 0, translation=[2.0 - dc, 0.0, 0.0])
        ref = bs.device("bot", "cam")
        bs.enable(ref, 8)
        img = bs.image(ref)
        assert not img[..., :3].any() and (img[..., 3] == 255).all()     # black before the first image (Webots)
        bs.step()
        rgb = img[..., 2::-1].astype(np.float64)
        for c, dc in enumerate(d):
            if not fog:
                assert (rgb[c] == byte(L)).all(), c
            else:
                w = (dc / 8.0) ** 2.2
                assert (rgb[c, 2, 5] == byte(L * (1.0 - w) + fog_lin * w)).all(), c
        if fog:                                       # the farther the wall, the greyer its centre
            assert len({img[c, 2, 5].tobytes() for c in range(len(d))}) == len(d)


def test_copies_never_see_each_others_robots(texture_dir: Path):
    """The scout parked 0.5 m in front of the rover in copy 0 and off in a corner in copy 1 (both
    copies with world seed 0): each copy's images are those of a Simulation with its scout where
    that copy has it, byte for byte (shadows included: the lamp and the sun cast them), and the
    noiseless housed camera's pixels differ between the two copies only where copy 0's scout
    (magenta) or its shadow (darker) is in view: copy 1's rover sees neither."""
    bs = scout_ahead_in_copy_0(_world(0, texture_dir), ("eye", "housed", "pano"), (-2.5, 2.5), "image")
    img = bs.image(bs.device("rover", "housed")).astype(np.int64)
    differ = (img[0] != img[1]).any(axis=-1)
    assert differ.sum() >= 4
    b, g, r = img[0][differ][:, 0], img[0][differ][:, 1], img[0][differ][:, 2]
    magenta = (r > g + 30) & (b > g + 30)               # the scout where copy 0 sees it
    shade = img[0][differ].sum(axis=-1) < img[1][differ].sum(axis=-1)    # or its shadow: darker
    assert magenta.any() and (magenta | shade).all()


def blocker_images(precision: str, **shape) -> np.ndarray:
    """The lit matte wall under a directional light along (1, 0.5, 0) that casts shadows, and a
    second robot, a 0.1 m box (``shape``: more of its fields): in copy 0 it stands between the wall's
    centre point and the light (out of the centre pixel's ray), in copy 1 far off. Each copy's image,
    checked to be the single Simulation's with that robot where the copy has it, byte for byte."""
    w = _facing([1.0], fog=False)
    data = w.model_dump(mode="json", exclude_none=True)
    data["lights"] = [{"type": "DirectionalLight", "direction": [1, 0.5, 0], "intensity": 0.7,
                       "ambient_intensity": 0.2, "cast_shadows": True}]
    data["robots"].append({"name": "blocker", "pose": {"translation": [5.0, 5.0, 0.0]},
                           "shapes": [{"pose": {"translation": [0, 0, 0.1]},
                                       "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}, **shape}]})
    lw = LoadedWorld(world=wm.World.model_validate(data), source="<test>", base_dir=Path.cwd())
    return images_with_robot_placed(lw, precision, "blocker", [[1.5, -0.25, 0.0], [-3.0, 3.0, 0.0]])


def images_with_robot_placed(lw: LoadedWorld, precision: str, robot: str, places: list) -> np.ndarray:
    """A copy of ``lw`` per place, ``robot`` put there by set_pose (and in a Simulation per copy alike),
    one step with robot "bot"'s camera "cam" enabled at 8 ms: each copy's image, checked to be its
    Simulation's byte for byte."""
    bs = BatchedSimulation(lw, len(places), precision=precision)
    ref = bs.device("bot", "cam")
    bs.enable(ref, 8)
    singles = []
    for c, t in enumerate(places):
        bs.set_pose(c, bs.slot(robot), translation=t)
        single = Simulation(lw, precision=precision)
        single.robot(robot).set_pose(t)
        single.robot("bot").device("cam").enable(8)
        singles.append(single)
    return stepped_alike(bs, ref, singles)


def stepped_alike(bs: BatchedSimulation, ref, singles: list[Simulation]) -> np.ndarray:
    """One step of the batched simulation and of each copy's Simulation: copy c's image of camera ``ref``
    (bot/cam) the bytes of ``singles[c]``'s; the batched images."""
    bs.step()
    img = bs.image(ref)
    for c, single in enumerate(singles):
        single.step()
        assert img[c].tobytes() == single.robot("bot").device("cam").image.tobytes(), c
    return img


@pytest.mark.parametrize("precision", BOTH)
def test_a_robot_shadows_the_wall_in_its_own_copy_only(precision: str):
    """blocker_images: copy 0's centre pixel reads the ambient term alone, albedo x 0.2; copy 1's
    the full albedo x (0.2 + 0.7 N.L), N.L = 1/sqrt(1.25)."""
    img = blocker_images(precision)
    albedo = np.array([0.6, 0.3, 0.15])

    def byte(x: np.ndarray) -> np.ndarray:
        return np.floor(255.0 * (1.0 - np.exp(-x * 1.3)) ** (1.0 / 2.2) + 0.5)

    rgb = img[:, 2, 5, 2::-1].astype(np.float64)
    assert (rgb[0] == byte(albedo * 0.2)).all()
    assert (rgb[1] == byte(albedo * (0.2 + 0.7 / math.sqrt(1.25)))).all()


def test_template_recognition_and_exposure_changes_are_refused_in_one_line(texture_dir: Path):
    """A batched camera's template (its constants) refuses enabling recognition or segmentation
    (per copy: BatchedSimulation.recognition_enable, batched_recognition.py) and changing the exposure
    or the field of view (a Zoom's setFov) (the world file's are kept), in one line, changing nothing; a camera without a Recognition node
    refuses recognition through the simulation too."""
    bs = BatchedSimulation(_world(0, texture_dir), 1)
    ref = bs.device("rover", "eye")
    tpl = bs.template(ref)
    for call in (lambda: tpl.recognition_enable(16), lambda: tpl.enable_segmentation(True)):
        with pytest.raises(ValueError, match=r"^rover/eye: a batched camera's \w+ is enabled per copy \(Batched"):
            call()
    with pytest.raises(ValueError, match=r"^rover/eye: batched cameras keep the world file's exposure \(use Simulation\)$"):
        tpl.set_exposure(2.0)
    assert tpl.exposure == 1.6
    with pytest.raises(ValueError, match=r"^rover/eye: batched cameras keep the world file's field of view \(use Simulation\)$"):
        tpl.set_fov(0.5)
    assert tpl.fov == tpl.config.field_of_view
    with pytest.raises(ValueError, match=r"^rover/eye: this camera has no Recognition node$"):
        bs.recognition_enable(ref, 16)
    assert not bs.recognition.period.any()


gym = pytest.importorskip("gymnasium")

from sensorium.gym import Task  # noqa: E402

OBSERVED = {"eye": 32, "housed": 32}


def _task() -> Task:
    return Task(robot="rover", observations=OBSERVED, control_period_ms=32, max_steps=15)


@pytest.mark.parametrize("precision", BOTH)
def test_the_vector_env_observes_cameras_as_the_single_env(precision: str, texture_dir: Path):
    """A task observing a noisy anti-aliased camera and a housed one: uint8 (height, width, 3) RGB
    boxes; every sub-env equals the single env (rebuilt Simulation, and the one-copy batched engine,
    which "auto" now picks) with its seed, observations, rewards and poses bit for bit, across
    autoresets; a sub-env passes Gymnasium's checker."""
    n = 3
    world = _world(3, texture_dir)
    venv, singles = vector_beside_singles(world, _task(), n, precision)
    space = venv.single_observation_space
    assert space["eye"].shape == (12, 16, 3) and space["eye"].dtype == np.uint8
    _reset_both(venv, singles, 4)
    rng = np.random.default_rng(5)
    done = np.zeros(n, dtype=bool)
    ended = 0
    for t in range(35):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        resets, vobs = _step_both(venv, singles, a, done, t)
        ended += resets
        assert all(space[k].contains(vobs[k][0]) for k in OBSERVED)
        assert vobs["eye"][0].std() > 5.0                     # a picture, not a flat colour
    assert ended >= n                                           # autoresets happened
    check_sub_env(venv)
    venv.close()
