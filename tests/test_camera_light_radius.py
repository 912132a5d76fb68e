"""A point or spot light's ``radius`` in camera images, as Webots' renderer has it: WREN's shaders
(phong.frag, pbr.frag and their per-light stencil passes) skip a point or spot light's direct term
at a surface farther than ``radius`` from it (a hard cut: distance > radius; at the radius it still
lights) and leave the scene's ambient light alone; Webots' LightSensor never reads ``radius``.

Closed forms: a camera at the origin looking along +x at a white wall (face x = 1.95) lit by a
point (or spot) light at the camera, plus an ambient-only directional light: a pixel whose ray
meets the wall at distance d reads ``ambient + I·cos`` when d ≤ radius (today's value, bit for bit)
and ``ambient`` alone when d > radius (the image of the world without that light). The batched
camera gives every copy the single simulation's bytes, fixed and robot-carried lights alike."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging, shading
from sensorium.server.devices import light as light_math
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld
from tests._copies import copies_and_singles
from tests.test_batched_camera import PERIODS, _world, images_with_robot_placed

WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
        "appearance": {"base_color": [1.0, 1.0, 1.0]}}
AMBIENT = {"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.0, "ambient_intensity": 0.3}
CAM = {"width": 9, "height": 7, "field_of_view": 1.0}
BOTH = ["fast", "exact"]


def world(lights, cam: dict = CAM, devices=()) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5}, "solids": [WALL], "lights": list(lights),
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", **cam}, *devices]}]})


def shoot(w: wm.World, precision: str = "exact") -> np.ndarray:
    sim = Simulation(w, precision=precision)
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    return cam.image[:, :, [2, 1, 0]].astype(np.int64)


def byte(L: np.ndarray) -> np.ndarray:
    """Webots' HDR resolve at exposure 1, 8 bits."""
    return np.floor(255.0 * (1.0 - np.exp(-np.asarray(L))) ** (1.0 / 2.2) + 0.5).astype(np.int64)


def rays() -> tuple[np.ndarray, np.ndarray]:
    """Each pixel ray's distance from the camera to the wall's face x = 1.95, and its cosine there
    (the ray's x component: a light at the camera shines along the ray)."""
    c = wm.Camera.model_validate({"device": "Camera", "name": "x", **CAM})
    d = imaging.pixel_directions(imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection))[0]
    return 1.95 / d[..., 0], d[..., 0]


def point(radius: float | None, **extra) -> dict:
    out = {"type": "PointLight", "location": [0.0, 0.0, 0.0], "intensity": 0.8, **extra}
    return out if radius is None else {**out, "radius": radius}


def spot(radius: float | None) -> dict:
    out = {"type": "SpotLight", "location": [0.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0], "intensity": 0.8,
           "beam_width": 0.7, "cut_off_angle": 0.7}      # every pixel (half-diagonal < 0.7 rad) in the beam
    return out if radius is None else {**out, "radius": radius}


@pytest.mark.parametrize("precision", BOTH)
@pytest.mark.parametrize("make", [point, spot])
def test_a_light_lights_what_lies_within_its_radius_and_nothing_beyond(make, precision: str):
    d, cos = rays()
    assert 1.95 <= d.min() and d.max() < 2.3
    today = shoot(world([AMBIENT, make(None)]), precision)                  # the default radius, 100 m
    np.testing.assert_array_equal(today, byte((0.3 + 0.8 * cos)[..., None] * np.ones(3)))
    for radius in (2.3, 10.0, 1e9):                                         # beyond every pixel's surface: unchanged
        np.testing.assert_array_equal(shoot(world([AMBIENT, make(radius)]), precision), today)
    alone = shoot(world([AMBIENT]), precision)
    np.testing.assert_array_equal(alone, np.broadcast_to(byte(np.full(3, 0.3)), alone.shape))
    for radius in (0.0, 1.0, 1.9):                                          # short of the wall: the light is gone
        np.testing.assert_array_equal(shoot(world([AMBIENT, make(radius)]), precision), alone)
    u = np.unique(d)
    radius = float(u[len(u) // 2] + u[len(u) // 2 + 1]) / 2.0             # across the image: a disc, no pixel near it
    got = shoot(world([AMBIENT, make(radius)]), precision)
    inside = d <= radius
    assert inside.any() and not inside.all()
    np.testing.assert_array_equal(got[inside], today[inside])
    np.testing.assert_array_equal(got[~inside], alone[~inside])


def test_the_cut_takes_the_direct_term_only_and_a_surface_at_the_radius_is_lit():
    """WREN's ambient light is the scene's, not a light's direct term: a point light's own
    ambientIntensity still reaches a surface beyond its radius. The test is distance > radius."""
    got = shoot(world([point(1.0, ambient_intensity=0.25)]))
    np.testing.assert_array_equal(got, np.broadcast_to(byte(np.full(3, 0.25)), got.shape))
    lights = light_math.LightArrays.from_lights([
        light_math.Light(light_math.LightKind.POINT, position=(0.0, 0.0, 0.0), intensity=1.0, ambient_intensity=0.1,
                         radius=2.0),
        light_math.Light(light_math.LightKind.SPOT, position=(0.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0),
                         intensity=0.5, beam_width=1.0, cut_off_angle=1.0, radius=2.0)])
    P = np.array([[1.5, 0.0, 0.0], [2.0, 0.0, 0.0], [np.nextafter(2.0, 3.0), 0.0, 0.0], [3.0, 0.0, 0.0]])
    N = np.tile([-1.0, 0.0, 0.0], (4, 1))
    L = shading.radiance(P, N, np.ones((4, 3)), lights)
    np.testing.assert_array_equal(L[:, 0], [1.6, 1.6, 0.1, 0.1])


def test_light_sensors_ignore_the_radius():
    """Webots' LightSensor (WbLightSensor::computeLightMeasurement) never reads ``radius``."""
    sensor = {"device": "LightSensor", "name": "ls", "pose": {"translation": [0.0, 0.0, 0.0]}}
    lamp = {"type": "PointLight", "location": [3.0, 0.0, 0.0], "intensity": 0.8}
    values = []
    for radius in (100.0, 1.0):
        w = wm.World.model_validate({"world_info": {"basic_time_step": 16}, "lights": [{**lamp, "radius": radius}],
                                     "robots": [{"name": "r", "devices": [sensor]}]})
        sim = Simulation(w, precision="exact")
        ls = sim.device("r/ls")
        ls.enable(16)
        sim.run(1)
        values.append(ls.value)
    assert values[0] == values[1] == pytest.approx(800.0)       # E = 0.8 (c = 1, white), LUT x1000


def _facing(radius: float) -> LoadedWorld:
    """A bodiless robot whose camera faces the white wall; it carries a point light at the camera
    (``radius``); a fixed spot light behind it along +x (radius 3) and the ambient light; the two
    cast shadows (nothing hides them: shadow rays go out, from what lies within reach only)."""
    dev = {"device": "Camera", "name": "cam", "width": 11, "height": 5, "field_of_view": 1.0}
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False},
        "lights": [AMBIENT, {**spot(3.0), "location": [-1.0, 0.0, 0.0], "intensity": 0.4, "cast_shadows": True}],
        "solids": [WALL],
        "robots": [{"name": "bot", "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2,
                                                          "max_wheel_speed": 10.0},
                    "lights": [point(radius, intensity=0.6, cast_shadows=True)], "devices": [dev]}]})
    return LoadedWorld(world=w, source="<test>", base_dir=Path.cwd())


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_cuts_as_the_single_simulation(precision: str):
    """Copies standing 0.5 to 3.5 m from the wall: the carried light (radius 1) and the fixed spot
    (radius 3, at x = -1) light a copy's wall fully, partly or not at all; each copy's image is the
    single simulation's with the robot where the copy has it, byte for byte."""
    x = [1.4, 1.0, 0.9, 0.5, -1.0, -1.6]                  # the camera's distance to the face: 1.95 - x
    img = images_with_robot_placed(_facing(1.0), precision, "bot", [[xc, 0.0, 0.0] for xc in x])
    # the centre pixel (its ray along +x): carried light within 1 m, spot within 3 m of x = -1
    centre = img[:, 2, 5, 2::-1].astype(np.int64)
    for c, xc in enumerate(x):
        L = 0.3 + (0.6 if 1.95 - xc <= 1.0 else 0.0) + (0.4 if 1.95 + 1.0 <= 3.0 else 0.0)
        np.testing.assert_array_equal(centre[c], byte(np.full(3, L)), err_msg=str(c))
    assert len({img[c].tobytes() for c in range(len(x))}) >= 4


@pytest.mark.parametrize("precision", BOTH)
def test_no_shadow_ray_goes_towards_a_light_out_of_reach(precision: str):
    """The point light at the camera now casts shadows: a shadow ray goes from every pixel's surface
    while the wall is within its radius, from those within it when the radius crosses the image,
    from none beyond it; the image is the one without shadows each time (nothing hides the light)."""
    d, _ = rays()
    u = np.unique(d)
    across = float(u[len(u) // 2] + u[len(u) // 2 + 1]) / 2.0
    for radius, casting in ((10.0, d.size), (across, int((d <= across).sum())), (1.0, 0)):
        assert casting in (0, d.size) or 0 < casting < d.size
        sim = Simulation(world([AMBIENT, point(radius, cast_shadows=True)]), precision=precision)
        cam = sim.device("r/cam")
        cam.enable(16)
        sim.run(1)
        assert sim.counters["rays_camera"] == d.size + casting, radius
        got = cam.image[:, :, [2, 1, 0]].astype(np.int64)
        np.testing.assert_array_equal(got, shoot(world([AMBIENT, point(radius)]), precision))




@pytest.mark.parametrize("precision", BOTH)
def test_the_camera_world_with_short_radii_is_the_single_simulations_in_every_copy(precision: str, texture_dir: Path):
    """tests/worlds/camera.yaml with the spot light's radius 1.5 m and the lamp's shadow-casting bulb's
    0.9 m (both cut across the cameras' views): every copy's images equal those of
    a Simulation with its seed, byte for byte, and differ from the default radii's."""
    def short(seed: int) -> LoadedWorld:
        lw = _world(seed, texture_dir)
        w = lw.world
        lights = [w.lights[0].model_copy(update={"radius": 1.5}), *w.lights[1:]]
        lamp = w.solids[3]
        lamp = lamp.model_copy(update={"lights": [lamp.lights[0].model_copy(update={"radius": 0.9})]})
        return LoadedWorld(world=w.model_copy(update={"lights": lights, "solids": [*w.solids[:3], lamp, *w.solids[4:]]}),
                           source=lw.source, base_dir=lw.base_dir)

    seeds = [5, 6]
    bs, sims = copies_and_singles(short, seeds, precision, PERIODS)
    default = Simulation(_world(seeds[0], texture_dir), precision=precision)
    default.robot("rover").device("eye").enable(PERIODS["rover"]["eye"])
    differs = 0
    for _ in range(6):
        bs.step()
        default.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    assert bs.image(bs.device(robot, n))[c].tobytes() == s.robot(robot).device(n).image.tobytes()
        differs += default.robot("rover").device("eye").image.tobytes() != sims[0].robot("rover").device("eye").image.tobytes()
    assert differs > 0


def test_a_radius_changed_while_running_is_seen_at_the_next_image():
    """A Supervisor's change of a light's ``radius`` (``Scene.set_top_light``, as its field setter
    calls it): the camera's next image is cut by the new radius, and lit again when it grows."""
    sim = Simulation(world([AMBIENT, point(None)]), precision="exact")
    cam = sim.device("r/cam")
    cam.enable(16)
    sim.run(1)
    today = cam.image.copy()
    lamp = sim.scene.top_lights()[1]
    for radius, want in ((1.0, shoot(world([AMBIENT]))), (5.0, today[:, :, [2, 1, 0]].astype(np.int64))):
        sim.scene.set_top_light(1, lamp.model_copy(update={"radius": radius}))
        sim.run(1)
        np.testing.assert_array_equal(cam.image[:, :, [2, 1, 0]].astype(np.int64), want)
