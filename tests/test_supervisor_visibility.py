"""Webots' ``Node.setVisibility(fromNode, visible)`` (README "Supervisor"): a node, and what is inside it,
left out of what one Camera, Lidar or RangeFinder sees, or the Viewpoint's pictures; the other devices
keep seeing it; visible again, it is back. tests/worlds/supervisor_visibility.yaml: boss's devices at
(0, 0, 0.1) look along +x at a crate whose face is at x = 1.0 before a wall whose face is at x = 3.0; a
device the crate is hidden from reads exactly what it reads with the crate removed (the wall: ranges 3
times as long, the camera's image bit for bit that world's), the other camera still sees it."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import supervisor
from sensorium.server.sim import viewshot
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "supervisor_visibility.yaml"
BOSS, WALL, CRATE = 1, 2, 3           # node ids: the robot, the solids in world order
DEVICES = ("lidar", "depth", "cam", "other")


def _live(precision: str = "exact") -> Live:
    lv = Live(Simulation(load_world(WORLD), precision=precision))
    lv.ok(A, "attach", {"robot": "boss"})
    for name in DEVICES:
        lv.sim.device(f"boss/{name}").enable(16)
    return lv


def boss(lv: Live, item: str, args: dict) -> dict:
    return lv.ok(A, f"/boss/robot/{item}", args)


def seer(lv: Live, device: str) -> int:
    return boss(lv, "get_from_device", {"device": device})["node"]


def hide(lv: Live, node: int, device: str, visible: bool = False) -> None:
    assert boss(lv, "set_visibility", {"node": node, "from_node": seer(lv, device), "visible": visible}) == \
        {"success": True}


def readings(lv: Live) -> dict:
    lv.step(A, "boss", {"duration": 16})
    dev = lv.sim.device
    return {"lidar": np.asarray(dev("boss/lidar").range_image, dtype=np.float64)[0].copy(),
            "depth": np.asarray(dev("boss/depth").range_image, dtype=np.float64).copy(),
            "cam": dev("boss/cam").image.copy(), "other": dev("boss/other").image.copy()}


def without_crate(precision: str) -> dict:
    lv = _live(precision)
    boss(lv, "remove_node", {"node": CRATE})
    return readings(lv)


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_a_node_hidden_from_one_device_is_seen_through_by_it_only(precision):
    lv = _live(precision)
    before = readings(lv)
    assert before["lidar"][2] == pytest.approx(1.0, abs=1e-6)
    assert before["depth"][3, 4] == pytest.approx(1.0, abs=1e-6)
    assert list(before["cam"][3, 4]) == list(before["other"][3, 4]) and before["cam"][3, 4][2] > 150  # red (BGRA)
    gone = without_crate(precision)
    for device in ("lidar", "depth", "cam"):
        hide(lv, CRATE, device)
    hidden = readings(lv)
    # the wall behind it: each beam 3 times as long (two planes along x), the image that of the world without it
    np.testing.assert_allclose(hidden["lidar"], 3.0 * before["lidar"], rtol=1e-6)
    # EXACT: bit for bit; FAST: Embree's float32 cast on from just past the crate may differ in the last bit
    same = np.testing.assert_array_equal if precision == "exact" else \
        (lambda a, b: np.testing.assert_allclose(a, b, rtol=2e-7, atol=0))
    same(hidden["lidar"], gone["lidar"])
    same(hidden["depth"], gone["depth"])
    np.testing.assert_array_equal(hidden["cam"], gone["cam"])
    assert not np.array_equal(hidden["cam"], before["cam"])
    np.testing.assert_array_equal(hidden["other"], before["other"])       # not hidden from the other camera
    for device in ("lidar", "depth", "cam"):
        hide(lv, CRATE, device, visible=True)
    again = readings(lv)
    for device in DEVICES:
        np.testing.assert_array_equal(again[device], before[device])


def test_a_shape_inside_a_solid_hidden_is_hidden_as_its_solid():
    lv = _live()
    shape = boss(lv, "get_field", {"node": CRATE, "field": "children"})["value"][0]
    assert boss(lv, "get_from_id", {"id": shape})["type"] == "Shape"
    hide(lv, shape, "cam")
    np.testing.assert_array_equal(readings(lv)["cam"], without_crate("exact")["cam"])
    hide(lv, WALL, "cam")               # the wall too: the blue sky (BGRA) in every pixel
    assert (readings(lv)["cam"] == np.array([255, 0, 0, 255], dtype=np.uint8)).all()


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_a_robot_hidden_from_its_own_devices_keeps_its_body_out_of_their_view(precision):
    """tests/worlds/supervisor_visibility_self.yaml: the devices inside the robot's body box."""
    lv = Live(Simulation(load_world(REPO / "tests" / "worlds" / "supervisor_visibility_self.yaml"),
                         precision=precision))
    lv.ok(A, "attach", {"robot": "boss"})
    depth, cam = lv.sim.device("boss/depth"), lv.sim.device("boss/cam")
    depth.enable(16)
    cam.enable(16)
    lv.step(A, "boss", {"duration": 16})
    np.testing.assert_allclose(depth.range_image[3], 0.1, rtol=1e-6)      # the body's inner face
    inside = cam.image.copy()
    hide(lv, BOSS, "depth")
    lv.step(A, "boss", {"duration": 16})
    np.testing.assert_allclose(depth.range_image[3], 2.9, rtol=1e-6)      # the wall's face, planar depth
    np.testing.assert_array_equal(cam.image, inside)                      # not hidden from the camera
    hide(lv, BOSS, "cam")
    lv.step(A, "boss", {"duration": 16})
    assert list(cam.image[0, 4]) == [255, 0, 0, 255]                      # the blue sky above the wall (BGRA)
    hide(lv, BOSS, "depth", visible=True)
    lv.step(A, "boss", {"duration": 16})
    np.testing.assert_allclose(depth.range_image[3], 0.1, rtol=1e-6)
    # the lidar, mounted on the body it sees (its beams' hits on it kept in the body frame): the same rule
    lidar = lv.sim.device("boss/lidar")
    lidar.enable(16)
    lv.step(A, "boss", {"duration": 16})
    seen = np.asarray(lidar.range_image, dtype=np.float64)[0].copy()
    assert seen[2] == pytest.approx(0.1, abs=1e-6)
    hide(lv, BOSS, "lidar")
    lv.step(A, "boss", {"duration": 16})
    np.testing.assert_allclose(np.asarray(lidar.range_image, dtype=np.float64)[0], 29.0 * seen, rtol=1e-6)


def test_the_viewpoint_pictures_leave_a_hidden_node_out():
    lv = _live()
    shown = viewshot.render(lv.sim, 32, 24)
    viewpoint = next(n["node"] for n in (boss(lv, "get_from_id", {"id": i}) for i in range(4, 8))
                     if n["type"] == "Viewpoint")
    assert boss(lv, "set_visibility", {"node": CRATE, "from_node": viewpoint, "visible": False}) == {"success": True}
    gone = _live()
    boss(gone, "remove_node", {"node": CRATE})
    np.testing.assert_array_equal(viewshot.render(lv.sim, 32, 24), viewshot.render(gone.sim, 32, 24))
    assert not np.array_equal(viewshot.render(lv.sim, 32, 24), shown)


def test_from_must_be_a_camera_lidar_range_finder_or_the_viewpoint_and_pairs_are_bounded(monkeypatch):
    lv = _live()
    msg = lv.err(A, "/boss/robot/set_visibility", {"node": CRATE, "from_node": WALL, "visible": False},
                 ErrorCode.INVALID_ARGUMENT)
    assert "is not the viewpoint or a camera, lidar or range-finder device" in msg
    monkeypatch.setattr(supervisor, "MAX_HIDDEN", 2)
    hide(lv, CRATE, "cam")
    hide(lv, WALL, "cam")
    hide(lv, WALL, "cam")                # hiding it again is no new pair
    msg = lv.err(A, "/boss/robot/set_visibility", {"node": CRATE, "from_node": seer(lv, "other"), "visible": False},
                 ErrorCode.INVALID_ARGUMENT)
    assert "at most 2 pairs" in msg
    hide(lv, WALL, "cam", visible=True)
    hide(lv, CRATE, "other")
    assert lv.sim.device("boss/other").hidden == {CRATE: lv.sim.device("boss/cam").hidden[CRATE]}


EXPECTED = ["before 1 207", "hidden 3 167", "other 207", "again 1 207", "bad from"]


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_python_supervisor_hides_the_crate_from_its_camera_and_lidar(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_visibility.py", "boss")
    assert ctl.out == EXPECTED
    assert ctl.stderr().count("Error:") == 1, ctl.stderr()


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_hides_the_crate_the_same_way(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller
    from test_supervisor_proto_fields import SAN_ENV

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_visibility.c")
    ctl = run_paused(WORLD, tmp_path, exe, "boss", env=SAN_ENV)
    assert ctl.out == EXPECTED
    assert ctl.stderr().count("Error:") == 1 and "Sanitizer" not in ctl.stderr(), ctl.stderr()


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_a_node_hidden_from_a_camera_casts_no_shadow_in_its_image(precision, tmp_path):
    """Webots sets a hidden node invisible for that camera's render, and WREN builds its shadow volumes
    from the visible nodes only: the crate hidden from ``cam`` leaves no shadow on the wall in cam's
    image -- the image of the world without the crate -- while ``other`` still sees the crate and, past
    its edges, its shadow (the sun behind the devices, along +x, casting shadows)."""
    import yaml

    data = yaml.safe_load(WORLD.read_text())
    data["lights"][0]["cast_shadows"] = True
    path = tmp_path / "shadows.yaml"
    path.write_text(yaml.safe_dump(data))

    def live() -> Live:
        lv = Live(Simulation(load_world(path), precision=precision))
        lv.ok(A, "attach", {"robot": "boss"})
        for name in ("cam", "other"):
            lv.sim.device(f"boss/{name}").enable(16)
        return lv

    def images(lv: Live) -> tuple[np.ndarray, np.ndarray]:
        lv.step(A, "boss", {"duration": 16})
        return lv.sim.device("boss/cam").image.copy(), lv.sim.device("boss/other").image.copy()

    lv = live()
    cam0, other0 = images(lv)
    gone = live()
    boss(gone, "remove_node", {"node": CRATE})
    cam_gone, _ = images(gone)
    hide(lv, CRATE, "cam")
    cam1, other1 = images(lv)
    np.testing.assert_array_equal(cam1, cam_gone)          # the wall fully lit: no shadow of the hidden crate
    np.testing.assert_array_equal(other1, other0)          # the other camera: the crate, and its shadow
    # the shadow was there to leave out: the wall's pixels behind the crate's edge are darker with it
    assert (other1[:, :, :3].astype(int).sum(axis=2) < cam1[:, :, :3].astype(int).sum(axis=2)).any()
    hide(lv, CRATE, "cam", visible=True)
    cam2, _ = images(lv)
    np.testing.assert_array_equal(cam2, cam0)
    # the Viewpoint's picture alike: hidden from it, the crate and its shadow are out of the picture
    shown = viewshot.render(lv.sim, 32, 24)
    viewpoint = next(n["node"] for n in (boss(lv, "get_from_id", {"id": i}) for i in range(4, 8))
                     if n["type"] == "Viewpoint")
    assert boss(lv, "set_visibility", {"node": CRATE, "from_node": viewpoint, "visible": False}) == {"success": True}
    np.testing.assert_array_equal(viewshot.render(lv.sim, 32, 24), viewshot.render(gone.sim, 32, 24))
    assert not np.array_equal(viewshot.render(lv.sim, 32, 24), shown)
