"""A Camera's Zoom (Webots' Zoom node): ``setFov`` within its range changes the field of view of the
images taken from then on. Closed form: a lit wall whose edge is seen at a known angle from the
camera; the edge's pixel column is where the pinhole formula puts it for each field of view. The
Zoom's range and Webots' error lines, the .wbt converter, a simulation reset, and the Python and C
clients alike."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation

W, H = 101, 9
FOV = 1.0
EDGE = 0.2          # rad: the wall's edge seen from the camera, to its left (+y)
FACE = 1.95         # the wall's face: x = 1.95


def world(zoom: dict | None = None) -> wm.World:
    edge_y = FACE * math.tan(EDGE)
    cam = {"device": "Camera", "name": "cam", "width": W, "height": H, "field_of_view": FOV}
    if zoom is not None:
        cam["zoom"] = zoom
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5},
        # the wall covers y <= edge_y (right of the edge as the camera sees it); black sky beyond
        "solids": [{"name": "wall", "pose": {"translation": [2.0, edge_y - 5.0, 0.0]},
                    "geometry": {"type": "box", "size": [0.1, 10.0, 20.0]}, "appearance": {"base_color": [1, 1, 1]}}],
        "lights": [{"type": "DirectionalLight", "direction": [1.0, 0.0, 0.0], "intensity": 1.0}],
        "robots": [{"name": "r", "devices": [cam]}]})


def lit_columns(fov: float) -> np.ndarray:
    """The pinhole formula: column c's centre ray makes tan = (W/2 - c - 1/2) / f to the left of the
    axis, f = (W/2) / tan(fov/2); it meets the wall where that tangent is below tan(EDGE)."""
    f = (W / 2) / math.tan(fov / 2)
    c = np.arange(W)
    return (W / 2 - c - 0.5) / f < math.tan(EDGE)


def seen(sim: Simulation) -> np.ndarray:
    cam = sim.device("r/cam")
    sim.run(1)
    return cam.image[H // 2, :, 2] > 0          # the centre row's red: the wall is lit, the sky black


def test_set_fov_moves_the_edge_to_where_the_pinhole_formula_puts_it():
    sim = Simulation(world({"min_field_of_view": 0.4, "max_field_of_view": 1.2}))
    cam = sim.device("r/cam")
    cam.enable(16)
    before = seen(sim)
    np.testing.assert_array_equal(before, lit_columns(FOV))
    assert before.argmax() == 32                # the first lit column: 50 - 92.5 tan 0.2 = 31.2
    cam.set_fov(FOV / 2)
    assert cam.describe()["fov"] == FOV / 2
    after = seen(sim)
    np.testing.assert_array_equal(after, lit_columns(FOV / 2))
    assert after.argmax() == 10                 # 50 - 197.9 tan 0.2 = 9.9
    k = np.frombuffer(cam.camera_info()["k"], dtype="<f8")
    assert k[0] == pytest.approx((W / 2) / math.tan(FOV / 4))      # camera_info follows
    sim.reset()                                 # the world file's field of view again
    assert cam.describe()["fov"] == FOV
    np.testing.assert_array_equal(seen(sim), lit_columns(FOV))


def test_the_zoom_range_and_what_set_fov_refuses():
    sim = Simulation(world({}))                 # Webots' defaults
    cam = sim.device("r/cam")
    d = cam.describe()
    assert (d["fov"], d["min_fov"], d["max_fov"]) == (FOV, 0.5, 1.5)
    for bad, why in [(0.45, r"out of the Zoom's range \[0.5, 1.5\]"), (1.6, "out of the Zoom's range"),
                     (math.nan, "finite"), (math.inf, "finite")]:
        with pytest.raises(ValueError, match=why):
            cam.set_fov(bad)
    assert cam.describe()["fov"] == FOV
    plain = Simulation(world()).device("r/cam")   # no Zoom: min = max = fov, nothing changes it
    d = plain.describe()
    assert (d["min_fov"], d["max_fov"]) == (FOV, FOV)
    with pytest.raises(ValueError, match="no Zoom node"):
        plain.set_fov(FOV)
    wide = Simulation(world({"min_field_of_view": 0.5, "max_field_of_view": 4.0})).device("r/cam")
    with pytest.raises(ValueError, match=r"planar camera \(it must be in \(0, pi\)\)"):
        wide.set_fov(math.pi)
    with pytest.raises(ValidationError, match="min_field_of_view .* is above max_field_of_view"):
        world({"min_field_of_view": 1.0, "max_field_of_view": 0.9})


EXPECTED = ["range 1 0.4 1.2", "edge 32", "refused 1", "fov 0.5", "edge 10"]
REFUSALS = ["Error: wb_camera_set_fov() called with 'fov' argument outside of the [0, pi] range.",
            "Error: wb_camera_set_fov() out of zoom range [0.400000, 1.200000]."]


def world_file(tmp_path) -> str:
    import yaml
    path = tmp_path / "zoom.yaml"
    path.write_text(yaml.safe_dump(world({"min_field_of_view": 0.4, "max_field_of_view": 1.2})
                                   .model_dump(mode="json", exclude_defaults=True)))
    return str(path)


def first_lit(cam) -> int:
    img = cam.getImage()
    return next((x for x in range(W) if cam.imageGetRed(img, W, x, H // 2) > 0), -1)


def test_the_python_client_zooms_and_follows_a_reset(tmp_path, capsys):
    """tests/c/zoom.c's lines from the Python client; then a simulation reset: the next step's
    reading brings the world file's field of view back to getFov."""
    from _inproc import inproc_server

    from sensorium.client import wb
    from sensorium.client.webots.controller import Robot
    with inproc_server(heartbeat_ms=5000, world=world_file(tmp_path)) as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/r")
        try:
            robot = Robot()
            cam = robot.getDevice("cam")
            lines = [f"range {cam.getFov():g} {cam.getMinFov():g} {cam.getMaxFov():g}"]
            cam.enable(16)
            robot.step(16)
            lines.append(f"edge {first_lit(cam)}")
            capsys.readouterr()
            cam.setFov(4.0)
            cam.setFov(0.3)
            assert capsys.readouterr().err.splitlines() == REFUSALS
            lines.append(f"refused {cam.getFov():g}")
            cam.setFov(0.5)
            lines.append(f"fov {cam.getFov():g}")
            assert core.sim.device("r/cam").fov == 0.5
            robot.step(16)
            lines.append(f"edge {first_lit(cam)}")
            assert lines == EXPECTED
            core.sim.reset()
            robot.step(16)
            assert cam.getFov() == FOV and first_lit(cam) == 32
        finally:
            wb.wb_robot_cleanup()
            Robot.created = None


@pytest.mark.slow
def test_the_c_client_zooms_as_the_python_client(tmp_path, tmp_path_factory):
    from test_c_client import REPO, sanitized_run
    code, out, err = sanitized_run(tmp_path_factory, REPO / "tests" / "c" / "zoom.c", world_file(tmp_path), "r")
    assert code == 0, err
    assert out == EXPECTED
    assert [x for x in err.splitlines() if x.startswith("Error")] == REFUSALS


def test_recognition_follows_the_new_field_of_view():
    """A recognised box's place and size on the image: Webots' projection (tests/test_recognition.py's
    webots_box) at the zoomed field of view, no longer at the world file's."""
    from test_recognition import aabb_corners, c_round

    w, h = 64, 48

    def box_on_image(fov: float) -> tuple[tuple[int, int], tuple[int, int]]:
        corners = aabb_corners(np.array([1.9, 0.1, -0.4]), np.array([2.1, 0.5, 0.2]))
        t = math.tan(fov / 2)
        u = np.clip(0.5 - 0.5 * (corners[:, 1] / np.abs(corners[:, 0])) / t, 0, 1)
        v = np.clip(0.5 - 0.5 * (corners[:, 2] / np.abs(corners[:, 0])) / (t * h / w), 0, 1)
        pu, pv = ((w - 1) * u).astype(int), ((h - 1) * v).astype(int)
        return ((c_round((pu.max() + pu.min()) / 2), c_round((pv.max() + pv.min()) / 2)),
                (math.ceil(pu.max() - pu.min()), math.ceil(pv.max() - pv.min())))

    sim = Simulation(wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "solids": [{"name": "crate", "pose": {"translation": [2.0, 0.3, -0.1]},
                    "geometry": {"type": "box", "size": [0.2, 0.4, 0.6]}, "recognition_colors": [[1, 0, 0]]}],
        "robots": [{"name": "r", "devices": [{"device": "Camera", "name": "cam", "width": w, "height": h,
                                              "field_of_view": 1.0, "recognition": {}, "zoom": {}}]}]}))
    cam = sim.device("r/cam")
    cam.recognition_enable(16)
    sim.step()
    [obj] = cam.objects
    assert (obj.position_on_image, obj.size_on_image) == box_on_image(1.0)
    cam.set_fov(0.6)
    sim.step()
    [obj] = cam.objects
    assert (obj.position_on_image, obj.size_on_image) == box_on_image(0.6) != box_on_image(1.0)
