"""Webots' Lens node on cameras and range finders (imaging.lens_source, pixel_directions' lens):
each output pixel's ray goes through the source coordinate Webots' lens shader samples (its formula
written out here, scalar by scalar), clamped to the image's edge pixels; zero coefficients give
today's images bit for bit (single and batched); a straight edge bends the way Webots' pincushion
bends it; a range finder's depths are the floor's closed form along the distorted rays; the batched
simulation's images equal the single one's byte for byte; the world file and the .wbt converter read
the node (Webots' centre resets). A spherical or cylindrical image's lens acts on each cube-face
sub-camera's image before the merge, as Webots renders it: the rays against the merge shader's face
lookup written out, a horizon pixel's and a wall edge's turn in closed form, a range finder's merged
face depths."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests._copies import copies_and_singles, steer_randomly

WORLDS = Path(__file__).parent / "worlds"
BOTH = ["fast", "exact"]


def webots_source(u: float, v: float, c: tuple[float, float], k: tuple[float, float], p: tuple[float, float]
                  ) -> tuple[float, float]:
    """The coordinate Webots' lens_distortion.frag samples for the output coordinate (u, v), one
    scalar at a time: x, y about the centre, r their squared length, the radial factor d1 and the
    divisor d2 = 1 / (1 + the trace of the model's Jacobian)."""
    x, y = u - c[0], v - c[1]
    r = x * x + y * y
    d1 = k[0] * r + k[1] * r * r
    d2 = 1.0 / (1.0 + 4.0 * k[0] * r + 6.0 * k[1] * r * r + 8.0 * p[0] * y + 8.0 * p[1] * x)
    return (u - d2 * (d1 * x + 2.0 * p[0] * x * y + p[1] * (r + 2.0 * x * x)),
            v - d2 * (d1 * y + 2.0 * p[1] * x * y + p[0] * (r + 2.0 * y * y)))


def pinhole_ray(u: float, v: float, fov: float, w: int, h: int) -> np.ndarray:
    """The unit planar ray through image coordinates (u, v) (v down), Webots' pinhole."""
    t = math.tan(fov / 2.0)
    d = np.array([1.0, (1.0 - 2.0 * u) * t, (1.0 - 2.0 * v) * t * h / w])
    return d / np.linalg.norm(d)


@pytest.mark.parametrize("samples", [imaging.SAMPLES_CENTRE, imaging.SAMPLES_2X2])
def test_each_samples_ray_goes_through_webots_source_coordinate(samples):
    """A 13 x 9 image (fov 1.1) through a lens with every coefficient (centre off the middle): every
    sample's ray is the pinhole ray through the shader's source coordinate, clamped to the span of
    the image's samples (Webots' clamp to the edge: a source beyond the image reads the edge pixel,
    whose centre is the clamp without anti-aliasing). Strong barrel distortion sends the corners'
    sources out of the image: they read exactly the edge's rays."""
    W, H, fov = 13, 9, 1.1
    g = imaging.ImageGeometry(W, H, fov)
    for c, k, p in (((0.45, 0.55), (0.3, -0.2), (0.01, -0.02)), ((0.5, 0.5), (-0.4, 0.0), (0.0, 0.0))):
        lens = imaging.Lens(c, k, p)
        dirs = imaging.pixel_directions(g, samples, lens)
        offs = [o[0] for o in samples]
        lo_u, hi_u = min(offs) / W, (W - 1 + max(offs)) / W
        offs_v = [o[1] for o in samples]
        lo_v, hi_v = min(offs_v) / H, (H - 1 + max(offs_v)) / H
        clamped = 0
        for s, (ox, oy) in enumerate(samples):
            for r in range(H):
                for j in range(W):
                    us, vs = webots_source((j + ox) / W, (r + oy) / H, c, k, p)
                    cu, cv = min(max(us, lo_u), hi_u), min(max(vs, lo_v), hi_v)
                    clamped += (cu, cv) != (us, vs)
                    np.testing.assert_allclose(dirs[s, r, j], pinhole_ray(cu, cv, fov, W, H), rtol=0, atol=1e-14)
        if k[0] < 0:
            assert clamped > 0                        # the barrel's corners read the image's edge
            if len(samples) == 1:                     # ... the corner pixel's own ray, exactly
                np.testing.assert_allclose(dirs[0, 0, 0], imaging.pixel_directions(g)[0, 0, 0], rtol=0, atol=1e-15)


def test_where_the_shaders_divisor_is_zero_a_pixel_keeps_its_own_ray():
    """A 2 x 2 image's pixel centres lie at r = 2·0.25² = 0.125 from the centre: with k1 = −2 the
    shader's divisor 1 + 4·k1·r is exactly 0 there (its source undefined, Webots' GPU divides by
    zero); each pixel keeps its undistorted ray rather than an infinite or NaN one."""
    g = imaging.ImageGeometry(2, 2, 1.0)
    assert imaging.pixel_directions(g, lens=imaging.Lens(radial=(-2.0, 0.0))).tobytes() == imaging.pixel_directions(g).tobytes()


# ---- spherical and cylindrical images: the lens on each cube-face sub-camera's image, then the merge

def nominal_ray(u: float, v: float, g: imaging.ImageGeometry) -> np.ndarray:
    """The merge shader's direction for the image coordinate (u, v), scalar by scalar (FLU)."""
    fov = g.field_of_view
    if g.projection == "cylindrical":
        a, e = (0.5 - u) * fov, (0.5 - v) * fov * g.height / g.width
        return np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    dx, dy = u - 0.5, v - 0.5
    rho = math.hypot(dx, dy)
    psi = rho * fov
    return np.array([math.cos(psi), -math.sin(psi) * dx / rho, -math.sin(psi) * dy / rho]) if rho else np.array([1.0, 0, 0])


def face_coords(d: np.ndarray) -> tuple[str, float, float]:
    """The merge shader's face and face coordinates ``coord`` (before its scaling) of a direction,
    each face's case written out as the shader has it (FLU: x front, y left, z up)."""
    x, y, z = d
    m = max(abs(x), abs(y), abs(z))
    if abs(x) == m:
        return ("front", y / m, z / m) if x > 0 else ("back", -y / m, z / m)
    if abs(y) == m:
        return ("left", -x / m, z / m) if y > 0 else ("right", x / m, z / m)
    return ("up", y / m, -x / m) if z > 0 else ("down", y / m, x / m)


def face_ray(face: str, a: float, b: float) -> np.ndarray:
    """The direction whose face coordinates on ``face`` are (a, b): face_coords' inverse."""
    d = {"front": (1.0, a, b), "back": (-1.0, -a, b), "left": (-a, 1.0, b), "right": (a, -1.0, b),
         "up": (-b, a, 1.0), "down": (b, a, -1.0)}[face]
    v = np.array(d)
    return v / np.linalg.norm(v)


def expected_face_lens_ray(u: float, v: float, g: imaging.ImageGeometry, c, k, p, tx: float, ty: float) -> np.ndarray:
    """The merged image's ray for (u, v) with a lens: the nominal ray's face and its pinhole
    coordinates (s, t) on the face's sub-image, the shader's source there, clamped to the face
    image's edge (a sample inside it), the face's ray through the source."""
    face, a, b = face_coords(nominal_ray(u, v, g))
    s, t = 0.5 * (1.0 - a / tx), 0.5 * (1.0 - b / ty)
    ss, ts = webots_source(s, t, c, k, p)
    if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0:
        ss, ts = min(max(ss, 0.0), 1.0), min(max(ts, 0.0), 1.0)
    return face_ray(face, (1.0 - 2.0 * ss) * tx, (1.0 - 2.0 * ts) * ty)


def test_the_sub_cameras_are_webots_set_field_of_view():
    """WbWrenCamera::setFieldOfView for a spherical camera: a field of view up to π/2 is the
    sub-camera's, its vertical one from the image's aspect; beyond π/2 the sub-camera's is π/2 and
    the aspect shrinks by (π/2)/fov; a vertical field beyond π/2 is π/2 with the aspect 1."""
    ext = imaging.sub_camera_extents
    assert ext(imaging.ImageGeometry(40, 20, 1.0, "cylindrical")) == pytest.approx((math.tan(0.5), math.tan(0.5) / 2), rel=1e-15)
    assert ext(imaging.ImageGeometry(64, 16, 6.0, "cylindrical")) == pytest.approx((1.0, 6.0 * 16 / 64 / (math.pi / 2)), rel=1e-15)
    assert ext(imaging.ImageGeometry(30, 30, 6.28, "spherical")) == pytest.approx((1.0, 1.0), rel=1e-15)
    assert ext(imaging.ImageGeometry(10, 30, 1.2, "cylindrical")) == pytest.approx((1.0, 1.0), rel=1e-15)


@pytest.mark.parametrize("projection, fov, W, H", [("spherical", 6.28, 30, 30), ("spherical", 3.0, 17, 13),
                                                   ("cylindrical", 6.0, 64, 16), ("cylindrical", 1.0, 40, 20)])
def test_each_sample_goes_through_its_cube_faces_lens_source(projection: str, fov: float, W: int, H: int):
    """Spherical and cylindrical images (six, five, four and one cube faces): every anti-aliasing
    sample's ray is the one the merge shader's face lookup gives through that face's lens pass —
    the nominal ray's face and face coordinates (the shader's cases written out), the pinhole
    coordinates on the face's sub-image, Webots' lens source about the face's own centre, clamped to
    the face image, and back to a direction on that face. A Lens of zero coefficients gives the
    rays of no lens, bit for bit."""
    g = imaging.ImageGeometry(W, H, fov, projection)
    tx, ty = imaging.sub_camera_extents(g)
    c, k, p = (0.45, 0.55), (0.3, -0.2), (0.01, -0.02)
    dirs = imaging.pixel_directions(g, imaging.SAMPLES_2X2, imaging.Lens(c, k, p))
    plain = imaging.pixel_directions(g, imaging.SAMPLES_2X2)
    faces = set()
    for s, (ox, oy) in enumerate(imaging.SAMPLES_2X2):
        for r in range(H):
            for j in range(W):
                u, v = (j + ox) / W, (r + oy) / H
                faces.add(face_coords(nominal_ray(u, v, g))[0])
                np.testing.assert_allclose(dirs[s, r, j], expected_face_lens_ray(u, v, g, c, k, p, tx, ty), rtol=0, atol=1e-14)
    assert len(faces) == {6.28: 6, 3.0: 5, 6.0: 6, 1.0: 1}[fov], faces
    assert imaging.pixel_directions(g, imaging.SAMPLES_2X2, imaging.Lens(c)).tobytes() == plain.tobytes()


def test_a_horizon_pixel_turns_by_the_radial_formula_on_each_face():
    """A cylindrical image spanning 2π (faces of half-extent 1 across), its middle row on the
    horizon: a pixel at angle β from its face's axis (β = its azimuth less the face's: 0 front,
    π/2 left, −π/2 right, π back) lies at x = −tan(β)/2 from the face image's centre, the shader's
    source at x·(1 + 3·k1·x²)/(1 + 4·k1·x²) (k2 = 0), so the ray stays on the horizon at the
    angle atan(tan β · (1 + 3·k1·tan²β/4)/(1 + k1·tan²β)) from the face's axis."""
    W, H, fov, k1 = 72, 9, 2.0 * math.pi, 0.4
    g = imaging.ImageGeometry(W, H, fov, "cylindrical")
    dirs = imaging.pixel_directions(g, lens=imaging.Lens(radial=(k1, 0.0)))[0, H // 2]
    for j in range(W):
        az = (0.5 - (j + 0.5) / W) * fov
        axis = min((0.0, math.pi / 2, -math.pi / 2, math.pi, -math.pi), key=lambda f: abs(az - f))
        tb = math.tan(az - axis)
        want = axis + math.atan(tb * (1.0 + 3.0 * k1 * tb * tb / 4.0) / (1.0 + k1 * tb * tb))
        assert dirs[j, 2] == 0.0
        assert math.atan2(dirs[j, 1], dirs[j, 0]) == pytest.approx(math.remainder(want, 2 * math.pi), abs=1e-13), j


def _cylinder_world(lens: dict | None, device: str) -> wm.World:
    """A cylindrical device (81 x 9, fov π) 0.5 m up, level, before a wall at x = 2 (2 m high) whose
    right edge is y = −1.4: the horizon row sees the wall for azimuths above atan(−1.4/2), the sky
    (0.2, 0.4, 0.6) beyond."""
    dev = {"device": device, "name": "cam", "pose": {"translation": [0.0, 0.0, 0.5]}, "width": 81, "height": 9,
           "field_of_view": math.pi, "projection": "cylindrical"}
    if device == "RangeFinder":
        dev.update(min_range=0.01, max_range=20.0)
    if lens is not None:
        dev["lens"] = lens
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False},
        "background": {"sky_color": [0.2, 0.4, 0.6]},
        "lights": [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.8, "ambient_intensity": 0.2}],
        "solids": [{"name": "wall", "pose": {"translation": [2.5, 8.6, 0.5]}, "geometry": {"type": "box", "size": [1.0, 20.0, 2.0]},
                    "appearance": {"base_color": [0.9, 0.5, 0.1]}}],
        "robots": [{"name": "bot", "devices": [dev]}]})


def _shot(world: wm.World, precision: str, kind: str) -> np.ndarray:
    sim = Simulation(LoadedWorld(world=world, source="<test>", base_dir=Path.cwd()), precision=precision)
    dev = sim.robot("bot").device("cam")
    dev.enable(8)
    sim.step()
    return dev.image.copy() if kind == "Camera" else dev.range_image.copy()


@pytest.mark.parametrize("precision", BOTH)
def test_a_cylindrical_cameras_lens_moves_a_walls_edge_by_the_formula(precision: str):
    """The wall's vertical edge at azimuth atan(−0.7) on the front face (the image spans π: its
    middle half is the front face, its sides the left and right faces): without a lens the horizon
    pixels left of the edge see the wall; with k1 = −1 (barrel) a horizon pixel at azimuth α sees
    the wall exactly where its ray's angle atan(tan α·(1 + 3·k1·tan²α/4)/(1 + k1·tan²α)) (at most
    the face's edge, 45°: the lens pass clamps to its image) is above the edge's, so the edge moves
    towards the centre — here by one pixel."""
    W, k1 = 81, -1.0
    edge = math.atan(-0.7)

    def wall_pixels(lens: dict | None) -> np.ndarray:
        img = _shot(_cylinder_world(lens, "Camera"), precision, "Camera")[4, :, :3]
        sky = img[-1].copy()                      # the far right: azimuth near −π/2, beyond the wall
        return ~(img == sky).all(axis=-1)

    plain, bent = wall_pixels(None), wall_pixels({"radial_coefficients": [k1, 0.0]})
    az = np.array([(0.5 - (j + 0.5) / W) * math.pi for j in range(W)])
    front = np.abs(az) < math.pi / 4
    t = np.tan(az)
    turned = np.arctan(np.clip(t * (1.0 + 3.0 * k1 * t * t / 4.0) / (1.0 + k1 * t * t), -1.0, 1.0))
    assert (np.abs(turned[front] - edge) > 1e-3).all()        # no ray grazes the edge
    np.testing.assert_array_equal(plain[front], az[front] > edge)
    np.testing.assert_array_equal(bent[front], turned[front] > edge)
    assert plain[front].sum() - bent[front].sum() == 1


@pytest.mark.parametrize("precision", BOTH)
def test_a_cylindrical_range_finder_keeps_webots_merge_of_face_depths(precision: str):
    """Webots' merge divides each face's planar depth by the nominal ray's cosine with the face's
    axis: on the front face, the wall x = 2 has the planar depth 2 wherever the lens sends a ray, so
    every horizon pixel there that sees the wall reads 2/cos(α) with its nominal azimuth α — the
    lens's own image of a plane facing the camera — not the distance along its turned ray."""
    W, k1 = 81, -1.0
    got = _shot(_cylinder_world({"radial_coefficients": [k1, 0.0]}, "RangeFinder"), precision, "RangeFinder")[4]
    plain = _shot(_cylinder_world(None, "RangeFinder"), precision, "RangeFinder")[4]
    az = np.array([(0.5 - (j + 0.5) / W) * math.pi for j in range(W)])
    t = np.tan(az)
    turned = np.arctan(np.clip(t * (1.0 + 3.0 * k1 * t * t / 4.0) / (1.0 + k1 * t * t), -1.0, 1.0))
    sees = (np.abs(az) < math.pi / 4) & (turned > math.atan(-0.7))
    assert sees.sum() > 10
    np.testing.assert_allclose(got[sees], 2.0 / np.cos(az[sees]), rtol=2e-7)
    # ... where the distance along the turned ray, 2/cos(turned), is another value
    assert (sees & (np.abs(2.0 / np.cos(turned) - 2.0 / np.cos(az)) > 1e-3)).sum() > 10
    front = np.abs(az) < math.pi / 4
    np.testing.assert_allclose(plain[front & (az > math.atan(-0.7))], 2.0 / np.cos(az[front & (az > math.atan(-0.7))]), rtol=2e-7)
    assert np.isinf(got[front & ~sees]).all() and (front & ~sees & (az > math.atan(-0.7))).any()


def _with_lens(world: wm.World, lens: dict | None, names: set[str]) -> wm.World:
    """``world`` with ``lens`` on the devices called ``names``."""
    robots = []
    for robot in world.robots:
        devices = [d.model_copy(update={"lens": None if lens is None else wm.Lens.model_validate(lens)})
                   if d.name in names else d for d in robot.devices]
        robots.append(robot.model_copy(update={"devices": devices}))
    return world.model_copy(update={"robots": robots})


def _loaded(path: Path, seed: int, lens: dict | None, names: set[str], base: Path | None = None) -> LoadedWorld:
    lw = load_world(path)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=_with_lens(w, lens, names), source=lw.source, base_dir=base or lw.base_dir)


ZERO = {"center": [0.3, 0.7]}                                   # no coefficients: no distortion
LENS = {"center": [0.48, 0.53], "radial_coefficients": [0.35, -0.4], "tangential_coefficients": [0.02, -0.015]}
CAMERAS = {"rover": {"eye": 16, "housed": 16, "pano": 32}}     # eye: anti-aliasing, noise; pano: cylindrical
DEPTHS = {"rover": {"depth": 16, "housed": 16, "wide": 32}}    # depth: noise, resolution; wide: cylindrical


def _images(sim, periods: dict, kind: str) -> list[bytes]:
    out = []
    for robot, names in periods.items():
        for n in names:
            d = sim.robot(robot).device(n)
            out.append((d.image if kind == "camera" else d.range_image).tobytes())
    return out


def _batched_images(bs, periods: dict, kind: str, c: int) -> list[bytes]:
    out = []
    for robot, names in periods.items():
        for n in names:
            ref = bs.device(robot, n)
            out.append((bs.image(ref) if kind == "camera" else bs.range_image(ref))[c].tobytes())
    return out


@pytest.mark.parametrize("precision", BOTH)
@pytest.mark.parametrize("kind", ["camera", "depth"])
def test_batched_lens_images_equal_the_single_ones_and_zero_coefficients_change_nothing(kind: str, precision: str,
                                                                                        texture_dir: Path):
    """The camera world (textured floor, lights, shadows, fog) and the depth world, their robots
    driving with random wheel commands: with a lens with every coefficient on the planar devices (a
    camera with anti-aliasing and noise, a housed one; range finders with noise and resolution, a
    housed one), every copy's images equal the single Simulation's with that copy's seed byte for
    byte, and they differ from the undistorted ones; with a Lens of zero coefficients (and an
    off-centre centre) the images are those without a lens, bit for bit, single and batched."""
    path, periods, names, base = ((texture_dir / "camera.yaml", CAMERAS, {"eye", "housed", "pano"}, texture_dir)
                                  if kind == "camera" else (WORLDS / "depth.yaml", DEPTHS, {"depth", "housed", "wide"}, None))
    seeds = [5, 9]
    runs = {}
    for name, lens in (("none", None), ("zero", ZERO), ("lens", LENS)):
        bs, sims = copies_and_singles(lambda s, lens=lens: _loaded(path, s, lens, names, base), seeds, precision, periods)
        rng = np.random.default_rng(2)
        frames = []
        for step in range(36):
            if step % 12 == 0:
                steer_randomly(bs, sims, rng, periods)
            bs.step()
            for c, s in enumerate(sims):
                s.step()
                want = _images(s, periods, kind)
                assert _batched_images(bs, periods, kind, c) == want, (name, step, c)
                frames.append(want)
        runs[name] = frames
    assert runs["zero"] == runs["none"]
    lens_frames, plain = np.array(runs["lens"], dtype=object), np.array(runs["none"], dtype=object)
    assert (lens_frames[:, :2] != plain[:, :2]).any()       # the planar devices' images changed
    assert (lens_frames[:, 2] != plain[:, 2]).any()         # and the cylindrical one's (its cube faces')


def _edge_world(lens: dict | None) -> wm.World:
    """A camera 0.5 m up (41 x 31, fov 1.2) facing a wide wall at x = 2 whose top edge (z = 1.1) is a
    horizontal line above the image's centre, the sky (0.2, 0.4, 0.6) above it; a directional light."""
    cam = {"device": "Camera", "name": "cam", "pose": {"translation": [0.0, 0.0, 0.5]}, "width": 41, "height": 31,
           "field_of_view": 1.2}
    if lens is not None:
        cam["lens"] = lens
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False},
        "background": {"sky_color": [0.2, 0.4, 0.6]},
        "lights": [{"type": "DirectionalLight", "direction": [1, 0, 0], "intensity": 0.8, "ambient_intensity": 0.2}],
        "solids": [{"name": "wall", "pose": {"translation": [2.5, 0.0, 0.0]}, "geometry": {"type": "box", "size": [1.0, 40.0, 2.2]},
                    "appearance": {"base_color": [0.9, 0.5, 0.1]}}],
        "robots": [{"name": "bot", "devices": [cam]}]})


@pytest.mark.parametrize("precision", BOTH)
def test_a_straight_edge_bends_as_webots_lens_bends_it(precision: str):
    """Without a lens the wall's top edge is one row across the image. With k1 = 1 (pincushion: each
    pixel samples nearer the centre) every pixel is sky exactly where its source coordinate lies
    above the edge's line in the pinhole image (v_edge = (1 − (0.6/2)/(tan 0.6·31/41))/2), and the edge
    lies farther from the centre at the image's sides than in its middle; k1 = −0.4 (barrel) bends it
    the other way."""
    W, H, fov = 41, 31, 1.2
    t = math.tan(fov / 2.0)
    v_edge = (1.0 - (0.6 / 2.0) / (t * H / W)) / 2.0
    sky = None

    def is_sky(lens: dict | None) -> np.ndarray:
        nonlocal sky
        sim = Simulation(LoadedWorld(world=_edge_world(lens), source="<test>", base_dir=Path.cwd()), precision=precision)
        cam = sim.robot("bot").device("cam")
        cam.enable(8)
        sim.step()
        img = cam.image[..., :3]
        if sky is None:
            sky = img[0, W // 2].copy()
        return (img == sky).all(axis=-1)

    plain = is_sky(None)
    rows = plain.sum(axis=0)                  # sky rows per column: the edge's row
    assert (rows == rows[0]).all() and 0 < rows[0] < H // 2
    above = {}
    for k1 in (1.0, -0.4):
        got = is_sky({"radial_coefficients": [k1, 0.0]})
        want = np.zeros((H, W), dtype=bool)
        for r in range(H):
            for j in range(W):
                us, vs = webots_source((j + 0.5) / W, (r + 0.5) / H, (0.5, 0.5), (k1, 0.0), (0.0, 0.0))
                vs = min(max(vs, 0.5 / H), (H - 0.5) / H)
                assert abs(vs - v_edge) > 1e-6            # no pixel's source on the edge itself
                want[r, j] = vs < v_edge
        assert (got == want).all(), k1
        above[k1] = got.sum(axis=0)
    mid = W // 2
    assert above[1.0][0] < above[1.0][mid] and above[1.0][-1] < above[1.0][mid]        # pincushion: sides farther up
    assert above[-0.4][0] > above[-0.4][mid] and above[-0.4][-1] > above[-0.4][mid]    # barrel: sides nearer the centre


@pytest.mark.parametrize("precision", BOTH)
def test_a_range_finders_depths_follow_the_distorted_rays(precision: str):
    """A range finder 0.3 m above an endless floor (the plane z = 0), looking level (24 x 18, fov 1.0,
    max_range 50): each pixel below the horizon reads the planar depth of the floor point its
    distorted ray meets, 0.3/((2·vs − 1)·tan(0.5)·18/24) with vs the shader's source row (closed
    form, float32), the pixels whose source is above the horizon +inf."""
    W, H, fov, h = 24, 18, 1.0, 0.3
    k, p = (0.25, 0.1), (0.01, 0.0)
    rf = {"device": "RangeFinder", "name": "rf", "pose": {"translation": [0.0, 0.0, h]}, "width": W, "height": H,
          "field_of_view": fov, "min_range": 0.01, "max_range": 50.0,
          "lens": {"radial_coefficients": list(k), "tangential_coefficients": list(p)}}
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False},
        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": [1000.0, 1000.0]}}],
        "robots": [{"name": "bot", "devices": [rf]}]})
    sim = Simulation(LoadedWorld(world=world, source="<test>", base_dir=Path.cwd()), precision=precision)
    dev = sim.robot("bot").device("rf")
    dev.enable(8)
    sim.step()
    got = dev.range_image
    t = math.tan(fov / 2.0)
    finite = 0
    for r in range(H):
        for j in range(W):
            us, vs = webots_source((j + 0.5) / W, (r + 0.5) / H, (0.5, 0.5), k, p)
            vs = min(max(vs, 0.5 / H), (H - 0.5) / H)
            down = (2.0 * vs - 1.0) * t * H / W
            depth = h / down if down > 0 else math.inf
            if depth < 50.0:
                finite += 1
                assert got[r, j] == pytest.approx(depth, rel=2e-6), (r, j)
            else:
                assert got[r, j] == np.inf, (r, j)
    assert finite > W * H // 3


def test_a_world_files_lens_is_read_with_webots_defaults_and_resets(tmp_path: Path):
    """A YAML camera's lens takes Webots' defaults (centre 0.5 0.5, zero coefficients); a centre
    component outside [0, 1] is reset as WbLens::updateCenter does (negative: 0; y > 1 sets x to 1
    and keeps y, its slip), one warning each; a spherical image takes its lens silently (on its cube
    faces). Its CameraInfo stays the undistorted pinhole with ``d`` zeros."""
    p = tmp_path / "w.yaml"
    p.write_text(
        "robots:\n  - name: r\n    devices:\n"
        "      - {device: Camera, name: a, lens: {}}\n"
        "      - {device: Camera, name: b, lens: {center: [-0.2, 1.4], radial_coefficients: [0.1, 0.0]}}\n"
        "      - {device: RangeFinder, name: c, projection: spherical, field_of_view: 2.0, lens: {}}\n")
    lw = load_world(p)
    a, b, c = lw.world.robots[0].devices
    assert a.lens == wm.Lens() and a.lens.center == (0.5, 0.5) and a.lens.radial_coefficients == (0.0, 0.0)
    assert b.lens is not None and b.lens.center == (1.0, 1.4)
    assert lw.warnings == [
        "robots[0].devices[1].lens.center: x -0.2 < 0, set to 0",
        "robots[0].devices[1].lens.center: y 1.4 > 1: Webots sets x (not y) to 1 and keeps y 1.4, done the same here"]
    sim = Simulation(lw)
    assert sim.robot("r").device("c").lens == imaging.Lens() and sim.robot("r").device("a").lens == imaging.Lens()
    # CameraInfo: the undistorted pinhole, d zeros (Webots' mapping is not plumb_bob: README "Lens distortion")
    info = sim.robot("r").device("b").camera_info()
    assert info["distortion_model"] == "plumb_bob" and info["d"] == bytes(40)
    fx = 32.0 / math.tan(0.785398 / 2.0)
    assert np.frombuffer(info["k"], "<f8").tolist() == [fx, 0.0, 31.5, 0.0, fx, 31.5, 0.0, 0.0, 1.0]


def test_the_wbt_converter_reads_the_lens_node(tmp_path: Path):
    """A .wbt Camera's and RangeFinder's Lens nodes become the world's lens (absent fields Webots'
    defaults); a NULL lens is none; another node type there is an error at the field."""
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nRobot { name \"r\" children [\n"
                 "Camera { lens Lens { center 0.4 0.6 radialCoefficients 0.2 -0.05 tangentialCoefficients 0.01 0.02 } }\n"
                 "RangeFinder { lens Lens { radialCoefficients -0.1 0 } }\n"
                 "Camera { name \"plain\" lens NULL }\n] }\n")
    lw = load_world(p)
    cam, rf, plain = lw.world.robots[0].devices
    assert cam.lens == wm.Lens(center=(0.4, 0.6), radial_coefficients=(0.2, -0.05), tangential_coefficients=(0.01, 0.02))
    assert rf.lens == wm.Lens(radial_coefficients=(-0.1, 0.0))
    assert plain.lens is None
    assert lw.warnings == []
    bad = tmp_path / "bad.wbt"
    bad.write_text("#VRML_SIM R2023b utf8\nRobot { children [ Camera { lens Focus { } } ] }\n")
    with pytest.raises(Exception, match=r"bad.wbt: line 2, column 29: Camera.lens: expected a Lens node or NULL, got a Focus node"):
        load_world(bad)
