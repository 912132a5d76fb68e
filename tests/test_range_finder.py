"""RangeFinder (issue 23) against closed-form answers: the depth of a plane and of a sphere in every
pixel, for the three projections, FAST and EXACT; near clipping, min/max range, Webots' vertical
field of view of a non-square image; noise, resolution, determinism; laziness; topics (32FC1 and a
CameraInfo whose pinhole is the pixels' rays); the Python API (wb_* and the RangeFinder class)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import imaging
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, sanitize


def world(rf: dict, solids=(), robot_pose=None, **extra) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 3},
        "solids": list(solids),
        "robots": [{"name": "r", "pose": robot_pose or {"translation": [0.0, 0.0, 0.0]},
                    "devices": [{"device": "RangeFinder", "name": "rf", **rf}]}], **extra})


def image(w: wm.World, precision="exact", steps=1) -> tuple[Simulation, np.ndarray]:
    sim = Simulation(w, precision=precision)
    dev = sim.device("r/rf")
    dev.enable(16)
    sim.run(steps)
    return sim, dev.range_image


def rays(rf: dict) -> np.ndarray:
    c = wm.RangeFinder.model_validate({"device": "RangeFinder", "name": "x", **rf})
    return imaging.pixel_directions(imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection))[0]


def f32_close(got: np.ndarray, want: np.ndarray, precision: str) -> None:
    # EXACT: float64-exact, then one float32 rounding; FAST: Embree's float32 distance
    tol = dict(rtol=2e-7, atol=0) if precision == "exact" else dict(rtol=1e-6, atol=3e-6)
    np.testing.assert_allclose(got.astype(np.float64), want, **tol)


TILTED_WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0], "rotation": [0, 0, 1, 0.4]},
               "geometry": {"type": "box", "size": [0.01, 20.0, 20.0]}}


@pytest.mark.parametrize("precision", ["exact", "fast"])
@pytest.mark.parametrize("projection,fov", [("planar", 1.2), ("cylindrical", 2.0), ("spherical", 2.5)])
def test_plane_ranges_in_every_pixel(precision, projection, fov):
    rf = {"width": 24, "height": 16, "field_of_view": fov, "projection": projection, "max_range": 10.0}
    _, got = image(world(rf, [TILTED_WALL]), precision)
    d = rays(rf)
    # the wall's face towards the device: n·p = c, n = (cos .4, sin .4, 0), c = 2 cos .4 - 0.005
    n = np.array([math.cos(0.4), math.sin(0.4), 0.0])
    c = 2.0 * math.cos(0.4) - 0.005
    t = c / (d @ n)
    want = t * d[..., 0] if projection == "planar" else t       # planar: depth along +x; else along the ray
    far = (t <= 0) | (want >= 10.0)                             # away from it, or beyond max_range: +inf
    assert (np.isinf(got) == far).all() and (~far).sum() > 300
    f32_close(got[~far], want[~far], precision)
    if projection == "planar":          # a wall facing the device: the same depth in every pixel
        _, flat = image(world(rf, [{**TILTED_WALL, "pose": {"translation": [2.0, 0.0, 0.0]}}]), precision)
        f32_close(flat, np.full(flat.shape, 1.995), precision)


@pytest.mark.parametrize("precision", ["exact", "fast"])
@pytest.mark.parametrize("projection", ["planar", "spherical"])
def test_sphere_ranges(precision, projection):
    centre, radius = np.array([1.5, 0.2, -0.1]), 0.6
    rf = {"width": 40, "height": 30, "field_of_view": 1.4, "projection": projection, "max_range": 10.0}
    sphere = {"name": "ball", "pose": {"translation": centre.tolist()},
              "geometry": {"type": "sphere", "radius": radius, "subdivision": 5}}
    _, got = image(world(rf, [sphere]), precision)
    d = rays(rf)
    b = d @ centre
    disc = b * b - (centre @ centre - radius * radius)
    hit = disc >= 0
    t = np.where(hit, b - np.sqrt(np.where(hit, disc, 0.0)), np.inf)
    want = t * d[..., 0] if projection == "planar" else t
    # pixels whose ray grazes the sphere (within float32 reach of its rim) may go either way
    rim = np.abs(disc) < 1e-4
    assert (np.isinf(got) == ~hit)[~rim].all()
    both = hit & ~rim
    if precision == "exact":
        f32_close(got[both], want[both], precision)
    else:                 # FAST sees the sphere's circumscribed tessellation (README "Precision")
        np.testing.assert_allclose(got[both], want[both], atol=0.01)
    assert both.sum() > 200


def test_near_min_and_max_range():
    # a thin pane 0.05 m ahead (closer than near), a wall at 1 m, max_range 3: the pane is clipped
    pane = {"name": "pane", "pose": {"translation": [0.05, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.002, 1, 1]}}
    wall = {"name": "wall", "pose": {"translation": [1.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.01, 1, 1]}}
    rf = {"width": 5, "height": 5, "field_of_view": 0.5, "near": 0.1, "min_range": 0.1, "max_range": 3.0}
    _, got = image(world(rf, [pane, wall]))
    np.testing.assert_allclose(got, 0.995, rtol=2e-7)
    # min_range above the wall's depth: +inf, and the wall still occludes what is behind it
    back = {"name": "back", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.01, 9, 9]}}
    _, got = image(world({**rf, "min_range": 1.2, "max_range": 3.0}, [wall, back]))
    assert np.isinf(got).all()
    # beyond max_range, and no hit at all: +inf
    _, got = image(world({**rf, "max_range": 0.9}, [wall]))
    assert np.isinf(got).all()
    _, got = image(world(rf))
    assert np.isinf(got).all()


def test_vertical_field_of_view_of_a_non_square_image():
    # a floor 0.3 m below a planar 8-wide, 31-high device: row r sees it iff the ray's slope
    # (1 - 2(r+1/2)/H) tan(fov/2) H/W is below -0.3/depth of the far wall at 1 m (Webots' vertical fov)
    W, H, fov = 8, 31, 1.0
    floor = {"name": "floor", "pose": {"translation": [0, 0, -0.3]}, "geometry": {"type": "plane", "size": None}}
    wall = {"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.001, 50, 50]}}
    rf = {"width": W, "height": H, "field_of_view": fov, "max_range": 10.0}
    _, got = image(world(rf, [floor, wall]))
    slope = (1 - 2 * (np.arange(H) + 0.5) / H) * math.tan(fov / 2) * H / W
    floor_rows = slope < -0.3 / 0.9995
    col = got[:, 3].astype(np.float64)
    np.testing.assert_allclose(col[~floor_rows], 0.9995, rtol=2e-7)
    np.testing.assert_allclose(col[floor_rows], -0.3 / slope[floor_rows], rtol=2e-7)
    assert 0 < floor_rows.sum() < H
    g = imaging.ImageGeometry(W, H, fov, "planar")
    assert g.vertical_field_of_view == pytest.approx(2 * math.atan(math.tan(fov / 2) * H / W))


def test_noise_resolution_and_determinism():
    wall = {"name": "wall", "pose": {"translation": [2.0, 0, 0]}, "geometry": {"type": "box", "size": [0.01, 50, 50]}}
    rf = {"width": 64, "height": 48, "field_of_view": 0.6, "max_range": 10.0, "noise": 0.002}
    _, a = image(world(rf, [wall]), steps=3)
    _, b = image(world(rf, [wall]), steps=3)
    assert a.tobytes() == b.tobytes()                       # same seed, same bytes
    err = a.astype(np.float64) - 1.995
    assert abs(err.std() - 0.02) < 0.002 and abs(err.mean()) < 0.002     # σ = noise · max_range
    other = world(rf, [wall])
    other = other.model_copy(update={"world_info": other.world_info.model_copy(update={"random_seed": 4})})
    _, c = image(other, steps=3)
    assert c.tobytes() != a.tobytes()
    _, q = image(world({**rf, "noise": 0.0, "resolution": 0.25}, [wall]))
    assert np.all(q == np.float32(2.0))                     # floor(1.995/0.25 + 1/2) * 0.25


def test_lazy_and_its_rays_are_counted():
    wall = {"name": "wall", "pose": {"translation": [2.0, 0, 0]}, "geometry": {"type": "box", "size": [0.01, 5, 5]}}
    sim = Simulation(world({"width": 32, "height": 24}, [wall]))
    sim.run(5)
    assert sim.counters["rays_range_finder"] == 0 and sim.counters["engine_rays"] == 0
    sim.device("r/rf").enable(32)
    sim.run(4)                                              # 64 ms at a 16 ms basic step: 2 images
    assert sim.counters["rays_range_finder"] == 2 * 32 * 24
    assert sim.device("r/rf").measurements == 2


def test_fields_are_checked_and_sanitised():
    with pytest.raises(ValueError, match="planar range finder's field_of_view must be < pi"):
        world({"field_of_view": 3.2})
    w, warnings = sanitize(world({"near": 0.5, "min_range": 0.2, "max_range": 0.1}))
    rf = w.robots[0].devices[0]
    assert rf.near == 0.2 and rf.max_range == pytest.approx(1.2)
    assert any("near" in m for m in warnings) and any("max_range" in m for m in warnings)
    with pytest.raises(WorldError, match=r"pixels \(width × height\): 16,777,216 exceeds the limit"):
        Simulation(world({"width": 4096, "height": 4096}))


def test_topics_image_and_camera_info():
    # a small ball at a known point: the CameraInfo pinhole projects it onto the pixel that sees it
    centre = np.array([2.0, 0.3, -0.2])
    ball = {"name": "ball", "pose": {"translation": centre.tolist()}, "geometry": {"type": "sphere", "radius": 0.02}}
    sim = Simulation(world({"width": 64, "height": 48, "field_of_view": 1.0, "max_range": 5.0}, [ball]))
    core = Core(sim)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/rf/range_image"] == msgs.IMAGE and types["/r/rf/camera_info"] == msgs.CAMERA_INFO
    sim.device("r/rf").enable(16)
    sim.step()
    ctl = core.topics.controls["r/rf"]
    img = msgs.validate(msgs.IMAGE, core.topics.build(ctl, "range_image", sim.time_ms))
    assert (img.encoding, img.width, img.height, img.step) == ("32FC1", 64, 48, 256)
    assert img.data == sim.device("r/rf").range_image.astype("<f4").tobytes()
    info = msgs.validate(msgs.CAMERA_INFO, core.topics.build(ctl, "camera_info", sim.time_ms))
    k = np.frombuffer(info.k, dtype="<f8").reshape(3, 3)
    # FLU → image: u grows to the right (-y), v downwards (-z)
    u = k[0, 2] - k[0, 0] * centre[1] / centre[0]
    v = k[1, 2] - k[1, 1] * centre[2] / centre[0]
    got = sim.device("r/rf").range_image
    assert math.isfinite(got[round(v), round(u)])
    assert np.isfinite(got).sum() <= 4
    assert core.topics.reading(ctl) == {"range_image": img.data}
    # spherical: no pinhole, no CameraInfo topic
    core2 = Core(Simulation(world({"projection": "spherical"})))
    assert "/r/rf/camera_info" not in {t.name for t in core2.topics.topics}


def test_python_api_through_a_server(tmp_path):
    from _inproc import inproc_server

    from sensorium.client import wb
    path = tmp_path / "rf.yaml"
    import yaml
    w = world({"width": 6, "height": 4, "field_of_view": 0.8, "max_range": 4.0, "min_range": 0.05},
              [{"name": "wall", "pose": {"translation": [1.5, 0, 0]}, "geometry": {"type": "box", "size": [0.01, 9, 9]}}])
    w = w.model_copy(update={"robots": [w.robots[0].model_copy(update={"synchronization": True})]})
    path.write_text(yaml.safe_dump(w.model_dump(mode="json", exclude_defaults=True)))
    with inproc_server(heartbeat_ms=5000, world=path) as (_core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/r")
        try:
            from controller import RangeFinder, Robot
        except ImportError:
            from sensorium.client.webots.controller import RangeFinder, Robot
        try:
            robot = Robot()
            rf = robot.getDevice("rf")
            assert isinstance(rf, RangeFinder)
            assert (rf.getWidth(), rf.getHeight(), rf.getMaxRange(), rf.getMinRange()) == (6, 4, 4.0, 0.05)
            assert rf.getFov() == pytest.approx(0.8)
            assert rf.getRangeImage() == [0.0] * 24                 # zeros before the first image (Webots)
            rf.enable(16)
            robot.step(16)
            flat = rf.getRangeImage()
            assert flat == pytest.approx([1.495] * 24, rel=1e-6)
            rows = rf.getRangeImageArray()
            assert len(rows) == 4 and len(rows[0]) == 6
            assert RangeFinder.rangeImageGetDepth(flat, 6, 5, 3) == flat[3 * 6 + 5]
            buf = rf.getRangeImage(data_type="buffer")
            assert np.frombuffer(buf, dtype="<f4").tolist() == flat
            tag = rf.getTag()
            assert np.asarray(wb.wb_range_finder_get_range_image(tag)).tolist() == flat
            png = tmp_path / "depth.png"
            assert rf.saveImage(str(png), 100) == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
            from PIL import Image
            grey = np.asarray(Image.open(png))
            assert grey.shape == (4, 6, 3) and np.all(grey == int((1.495 - 0.05) / 4.0 * 255))
            assert rf.saveImage(str(tmp_path / "x.bmp"), 100) == -1
        finally:
            wb.wb_robot_cleanup()
            from sensorium.client.webots.controller.robot import Robot as _R
            _R.created = None


def test_image_and_camera_info_export_to_ros2_and_foxglove_cdr():
    from sensorium.schemas.wire import pack
    from sensorium.server.recording.export import CdrEncoder, to_ros, to_rosbags, typestore_for
    wall = {"name": "wall", "pose": {"translation": [1.0, 0, 0]}, "geometry": {"type": "box", "size": [0.01, 9, 9]}}
    sim = Simulation(world({"width": 8, "height": 6, "field_of_view": 0.9, "max_range": 5.0}, [wall]))
    core = Core(sim)
    sim.device("r/rf").enable(16)
    sim.step()
    ctl = core.topics.controls["r/rf"]
    store = typestore_for("jazzy")
    info = to_rosbags(store, msgs.CAMERA_INFO, to_ros(store, msgs.CAMERA_INFO, core.topics.build(ctl, "camera_info", 16)))
    fx = 4.0 / math.tan(0.45)
    np.testing.assert_allclose(info.k, [fx, 0, 3.5, 0, fx, 2.5, 0, 0, 1])
    assert info.width == 8 and info.height == 6 and info.distortion_model == "plumb_bob"
    enc = CdrEncoder("jazzy")
    for item, typ in (("range_image", msgs.IMAGE), ("camera_info", msgs.CAMERA_INFO)):
        body = pack(core.topics.build(ctl, item, 16))
        name, cdr = enc.encode(typ, body)
        assert name == typ and cdr == enc.encode_generic(typ, body)


def test_a_cylindrical_range_finder_and_lidar_see_the_same_ranges():
    """Webots' lidar_vs_range_finder idea: a cylindrical lidar of H layers spanning fov·(H−1)/W
    casts the rays of a W × H cylindrical range finder (same azimuths, same elevations), so both
    images agree in every pixel."""
    W, H, fov = 24, 9, 1.6
    solids = [TILTED_WALL, {"name": "ball", "pose": {"translation": [1.2, -0.3, 0.1]},
                            "geometry": {"type": "sphere", "radius": 0.3}}]
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "solids": solids,
        "robots": [{"name": "r", "devices": [
            {"device": "RangeFinder", "name": "rf", "width": W, "height": H, "field_of_view": fov,
             "projection": "cylindrical", "max_range": 8.0, "min_range": 0.01},
            {"device": "Lidar", "name": "lidar", "horizontal_resolution": W, "number_of_layers": H,
             "field_of_view": fov, "vertical_field_of_view": fov * (H - 1) / W, "max_range": 8.0, "min_range": 0.01}]}]})
    sim = Simulation(w)
    sim.device("r/rf").enable(16)
    sim.device("r/lidar").enable(16)
    sim.step()
    a, b = sim.device("r/rf").range_image, sim.device("r/lidar").range_image
    assert a.shape == b.shape == (H, W)
    np.testing.assert_allclose(a, b, rtol=1e-6)
    assert np.isfinite(a).sum() > W * H // 2
