"""A device never sees its own shapes (issue 27): an infra-red sensor inside its own small box and a
lidar inside its housing read what they read without them, while the rest of their robot stays in
view (Webots: a ray never sees a shape from inside it). Distances against closed forms."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world

BOTH = ["fast", "exact"]
WALL_X = 0.3          # the wall's face at x = 0.3 (a box 0.02 thick centred at 0.31)


def world(ir_box: bool = True, housing: bool = True, mark: bool = True, mast: bool = False, rotating: bool = False) -> dict:
    shapes = [{"pose": {"translation": [0, 0, 0.03]}, "geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}}]
    if ir_box:        # the sensor's own small box, around its origin (an e-puck's infra-red sensor)
        shapes.append({"pose": {"translation": [0.04, 0, 0.02]}, "geometry": {"type": "box", "size": [0.004, 0.008, 0.004]},
                       **({"of_device": "ir"} if mark else {})})
    if housing:       # the lidar's housing, around its origin (a SICK lidar)
        shapes.append({"pose": {"translation": [0, 0, 0.1]}, "geometry": {"type": "cylinder", "radius": 0.02, "height": 0.03},
                       **({"of_device": "lidar"} if mark else {})})
    if mast:          # part of the robot that is not the lidar's: it stays in view (Webots)
        shapes.append({"pose": {"translation": [0, 0.05, 0.1]}, "geometry": {"type": "box", "size": [0.01, 0.01, 0.1]}})
    lidar = {"device": "Lidar", "name": "lidar", "pose": {"translation": [0, 0, 0.1]}, "horizontal_resolution": 64,
             "field_of_view": 6.283185307179586, "number_of_layers": 1, "min_range": 0.01, "max_range": 2.0, "near": 0.01}
    if rotating:
        lidar |= {"type": "rotating", "default_frequency": 10, "min_frequency": 1, "max_frequency": 20}
    return {
        "world_info": {"basic_time_step": 16},
        "solids": [{"name": "wall", "pose": {"translation": [WALL_X + 0.01, 0, 0.1]},
                    "geometry": {"type": "box", "size": [0.02, 2, 0.2]}}],
        "robots": [{"name": "r", "shapes": shapes, "devices": [
            {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "pose": {"translation": [0.04, 0, 0.02]},
             "lookup_table": [[0, 0, 0], [1, 1000, 0]]},
            lidar]}],
    }


def beam(data: dict, direction) -> tuple[int, np.ndarray]:
    """The beam (column of layer 0) nearest a direction in the lidar frame, and its direction."""
    sim = Simulation(parse_world(copy.deepcopy(data)), "fast")
    dirs = sim.device("r/lidar")._all_dirs[0]
    j = int(np.argmax(dirs @ np.asarray(direction, dtype=np.float64)))
    return j, dirs[j]


def readings(data: dict, precision: str, steps: int = 4) -> tuple[float, np.ndarray]:
    sim = Simulation(parse_world(copy.deepcopy(data)), precision)
    sim.device("r/ir").enable(16)
    lidar = sim.device("r/lidar")
    lidar.enable(16)
    sim.run(steps)
    return sim.device("r/ir").value, lidar.range_image.copy()


@pytest.mark.parametrize("precision", BOTH)
def test_own_shapes_are_invisible_to_their_device(precision: str) -> None:
    ir, image = readings(world(), precision)
    ir_bare, image_bare = readings(world(ir_box=False, housing=False), precision)
    assert ir == ir_bare and np.array_equal(image, image_bare)       # bit for bit as without them
    assert ir == pytest.approx(1000 * (WALL_X - 0.04), rel=1e-6)      # the wall, white: D/F = D (fast: float32)
    j, d = beam(world(), (1, 0, 0))                                    # the wall along this beam: WALL_X / cos
    assert image[0, j] == pytest.approx(WALL_X / d[0], rel=1e-6)       # (float32 image)
    # the same shapes not marked as the devices' own: each sees its own shape from inside
    ir_seen, image_seen = readings(world(mark=False), precision)
    assert ir_seen < 1000 * 0.003 and np.all(image_seen <= 0.021)


@pytest.mark.parametrize("precision", BOTH)
@pytest.mark.parametrize("rotating", [False, True])
def test_the_rest_of_the_robot_stays_in_view(precision: str, rotating: bool) -> None:
    """The mast (the robot's, not the lidar's) is seen through the housing at its closed-form range."""
    _, image = readings(world(mast=True, rotating=rotating), precision, steps=8)
    if not rotating:    # (a rotating head's columns follow its sweep: compared with the bare robot below)
        j, d = beam(world(mast=True), (0, 1, 0))
        # the mast's face y = 0.045 (|x| <= 0.005 along the beams near +y): the range is 0.045 / d_y
        assert abs(d[0]) * 0.045 / d[1] < 0.005
        assert image[0, j] == pytest.approx(0.045 / d[1], rel=1e-6)
    assert np.count_nonzero(image < 0.06) >= 1     # the mast is in view
    _, bare = readings(world(housing=False, mast=True, rotating=rotating), precision, steps=8)
    if precision == "exact":
        assert np.array_equal(image, bare)
    else:     # FAST: the mast met in the body frame (mounted beams) vs in the world: float32 rounding
        np.testing.assert_allclose(image, bare, rtol=1e-6)


def test_wbt_device_children_are_marked_as_its_own(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" children [\n'
                 '  DistanceSensor { translation 0.04 0 0.02 name "ps0" type "infra-red" children [\n'
                 '    Shape { geometry Box { size 0.004 0.008 0.004 } } ] }\n'
                 '  DistanceSensor { name "ps0" children [ Shape { geometry Sphere { radius 0.002 } } ] }\n'
                 '  Camera { children [ Shape { geometry Box { size 0.01 0.01 0.01 } } ] }\n'
                 '  Shape { geometry Cylinder { radius 0.035 height 0.05 } } ] }\n')
    (robot,) = load_world(p).world.robots
    assert [(s.geometry.type, s.of_device) for s in robot.shapes] == [
        ("box", "ps0"), ("sphere", "ps0(1)"), ("box", "camera"), ("cylinder", None)]


def test_of_device_must_name_a_device_of_the_robot() -> None:
    from sensorium.server.world.loader import WorldError

    data = world()
    data["robots"][0]["shapes"][1]["of_device"] = "nope"
    with pytest.raises(WorldError, match=r"robots\[0\] \(r\)\.shapes\[1\]\.of_device: 'nope' is not a device of this robot"):
        parse_world(data)
    data = world()
    data["solids"][0]["shapes"] = [{"geometry": {"type": "sphere"}, "of_device": "ir"}]
    with pytest.raises(WorldError, match="only a robot's shapes belong to one of its devices"):
        parse_world(data)


# -- cameras and range finders follow the same rule (a camera housed in its own small box sees out)

DEV = np.array([0.05, 0.0, 0.05])     # the image device's origin, at the centre of its own 2 cm box
POST_X = 0.14                         # the face of a post of the robot's own (not the device's)


def image_world(kind: str, housing: bool = True, mark: bool = True, post: bool = False, ball: bool = False) -> dict:
    shapes = [{"pose": {"translation": [0, 0, 0.03]}, "geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}}]
    if housing:
        shapes.append({"pose": {"translation": DEV.tolist()}, "geometry": {"type": "box", "size": [0.02, 0.02, 0.02]},
                       "appearance": {"base_color": [0, 0, 1]}, **({"of_device": "eye"} if mark else {})})
    if post:
        shapes.append({"pose": {"translation": [POST_X + 0.01, 0, 0.05]}, "geometry": {"type": "box", "size": [0.02, 0.01, 0.2]},
                       "appearance": {"base_color": [0, 1, 0]}})
    device = {"device": kind, "name": "eye", "pose": {"translation": DEV.tolist()}, "width": 8, "height": 6,
              "field_of_view": 0.5, "near": 0.005}
    if kind == "RangeFinder":
        device |= {"min_range": 0.005, "max_range": 2.0}
    if ball:
        device["recognition"] = {"occlusion": 2, "segmentation": True}
    solids = ([{"name": "ball", "pose": {"translation": [0.25, 0, 0.05]}, "geometry": {"type": "sphere", "radius": 0.03},
                "recognition_colors": [[1, 0, 0]]}] if ball else
              [{"name": "wall", "pose": {"translation": [WALL_X + 0.01, 0, 0.05]}, "geometry": {"type": "box", "size": [0.02, 2, 1]},
                "appearance": {"base_color": [1, 0, 0]}}])
    return {"world_info": {"basic_time_step": 16}, "solids": solids,
            "lights": [{"type": "PointLight", "location": [-0.2, 0, 0.3], "intensity": 1}],
            "robots": [{"name": "r", "shapes": shapes, "devices": [device]}]}


def capture(data: dict, precision: str) -> np.ndarray:
    sim = Simulation(parse_world(copy.deepcopy(data)), precision)
    dev = sim.device("r/eye")
    dev.enable(16)
    sim.step()
    return dev.range_image.copy() if dev.kind == "RangeFinder" else dev.image.copy()


@pytest.mark.parametrize("precision", BOTH)
def test_a_range_finder_sees_out_of_its_own_box(precision: str) -> None:
    depth = capture(image_world("RangeFinder"), precision)
    # planar: every pixel holds the wall's depth, WALL_X - x of the device (the box is not there)
    np.testing.assert_allclose(depth, WALL_X - DEV[0], rtol=2e-7 if precision == "exact" else 1e-6)
    bare = capture(image_world("RangeFinder", housing=False), precision)
    if precision == "exact":
        assert np.array_equal(depth, bare)
    # the same box not marked as the device's: it sees the box's inside (1 cm in depth) everywhere
    np.testing.assert_allclose(capture(image_world("RangeFinder", mark=False), precision), 0.01, rtol=1e-5)


@pytest.mark.parametrize("precision", BOTH)
def test_a_range_finder_still_sees_the_rest_of_its_robot(precision: str) -> None:
    """A post of the robot stands in front of the housed device: the pixels whose rays meet its face
    (x = POST_X, |y| <= 5 mm, closed form from the pixel rays) read its depth, the others the wall's."""
    from sensorium.server.devices import imaging

    depth = capture(image_world("RangeFinder", post=True), precision)
    d = imaging.pixel_directions(imaging.ImageGeometry(8, 6, 0.5, "planar"))[0]
    t = (POST_X - DEV[0]) / d[..., 0]
    on_post = np.abs(t * d[..., 1]) <= 0.005
    assert 0 < on_post.sum() < on_post.size
    want = np.where(on_post, POST_X - DEV[0], WALL_X - DEV[0])
    np.testing.assert_allclose(depth, want, rtol=2e-7 if precision == "exact" else 1e-6)


@pytest.mark.parametrize("precision", BOTH)
def test_a_camera_sees_out_of_its_own_box(precision: str) -> None:
    image = capture(image_world("Camera"), precision)
    bare = capture(image_world("Camera", housing=False), precision)
    if precision == "exact":
        assert np.array_equal(image, bare)
    else:   # the wall met again from just past the box: float32 distances, the same colours to a unit
        assert np.abs(image.astype(int) - bare.astype(int)).max() <= 1
    bgr = image[:, :, :3].astype(int)
    assert (bgr[:, :, 2] > 50).all() and (bgr[:, :, 0] == 0).all()          # the red wall in every pixel
    seen = capture(image_world("Camera", mark=False), precision)[:, :, :3].astype(int)
    assert (seen[:, :, 0] > 50).all() and (seen[:, :, 2] == 0).all()        # unmarked: the blue box's inside


def test_recognition_pixel_rays_see_out_of_the_cameras_own_box() -> None:
    """Occlusion 2 and the segmentation image use the pixel rays: the ball in front is recognised
    and coloured from inside the camera's own box, as from a bare camera."""
    def run(data: dict):
        sim = Simulation(parse_world(copy.deepcopy(data)), "exact")
        cam = sim.device("r/eye")
        cam.recognition_enable(16)
        cam.enable_segmentation(True)
        sim.step()
        return [o.id for o in cam.objects], cam.segmentation_image.copy()

    objects, seg = run(image_world("Camera", ball=True))
    bare_objects, bare_seg = run(image_world("Camera", housing=False, ball=True))
    assert objects == bare_objects == [2] and np.array_equal(seg, bare_seg)
    assert (seg[:, :, 2] == 255).sum() > 0                                   # the ball's red pixels
    assert run(image_world("Camera", mark=False, ball=True))[0] == []       # unmarked: the box hides it


@pytest.mark.parametrize("precision", BOTH)
def test_the_batched_simulation_follows_the_same_rule(precision: str) -> None:
    """Infra-red and lidar with their own shapes (and a mast of the robot in view), two copies at
    different poses: each copy reads what the single simulation reads, bit for bit (the gym's
    engine="auto" runs such worlds batched)."""
    from sensorium.server.sim.batched import BatchedSimulation

    data = world(mast=True)
    bs = BatchedSimulation(parse_world(copy.deepcopy(data)), 2, precision=precision)
    sims = [Simulation(parse_world(copy.deepcopy(data)), precision) for _ in range(2)]
    bs.set_pose(1, 0, [0.05, 0.02, 0.0], rotation=[0, 0, 1, 0.3])
    sims[1].robot("r").set_pose([0.05, 0.02, 0.0], rotation=[0, 0, 1, 0.3])
    for n in ("ir", "lidar"):
        bs.enable(bs.device("r", n), 16)
        for s in sims:
            s.device(f"r/{n}").enable(16)
    bs.run(2)
    for c, s in enumerate(sims):
        s.run(2)
        assert s.device("r/ir").value == float(bs.value(bs.device("r", "ir"))[c])
        assert s.device("r/lidar").range_image.tobytes() == bs.range_image(bs.device("r", "lidar"))[c].tobytes()
    ir_bare, _ = readings(world(ir_box=False, housing=False), precision)
    assert float(bs.value(bs.device("r", "ir"))[0]) == ir_bare        # copy 0: the wall, not the sensor's box
    assert np.count_nonzero(bs.range_image(bs.device("r", "lidar"))[0] < 0.06) >= 1    # the mast


@pytest.mark.parametrize("precision", BOTH)
def test_a_housed_camera_sees_and_shades_the_rest_of_its_robot_as_a_bare_one(precision: str) -> None:
    """The robot turned and lit from the side: the post (the robot's, met in the body frame when the
    camera has shapes of its own) has the colours a bare camera gives it, so its normals are turned
    into the world with the robot."""
    def image(housing: bool) -> np.ndarray:
        data = image_world("Camera", housing=housing, post=True)
        data["robots"][0]["pose"] = {"rotation": [0, 0, 1, 0.7]}
        data["lights"] = [{"type": "PointLight", "location": [0, -0.5, 0.3], "intensity": 1}]
        return capture(data, precision)[:, :, :3].astype(int)

    housed, bare = image(True), image(False)
    assert np.abs(housed - bare).max() <= 1
    post = (housed[:, :, 1] > 50) & (housed[:, :, 2] == 0)          # green, not the red wall
    assert 0 < post.sum() < post.size


@pytest.mark.parametrize("precision", BOTH)
def test_a_housed_rotating_lidar_beside_another_lidar_reads_as_alone(precision: str) -> None:
    """Each lidar's scan is a cast of its own (Simulation._cast_batched): a housed rotating lidar
    stepped beside a fixed lidar due in the same steps reads bit for bit what it reads alone, its
    housing unseen. (Joined with the fixed lidar's rays, its beams lost their mounting and met the
    housing at 0.02 m; and FAST traced a joined cast as incoherent packets, a lone scan as coherent
    ones, which can differ for a beam grazing an edge.)"""
    data = world(ir_box=False, rotating=True)
    data["robots"][0]["devices"].append({"device": "Lidar", "name": "other", "pose": {"translation": [0, 0, 0.15]},
                                         "horizontal_resolution": 32, "field_of_view": 3.0, "number_of_layers": 1,
                                         "max_range": 2.0})

    def image(beside: bool) -> np.ndarray:
        sim = Simulation(parse_world(copy.deepcopy(data)), precision)
        sim.device("r/lidar").enable(16)
        if beside:
            sim.device("r/other").enable(16)
        sim.run(8)      # 10 Hz x 16 ms x 64 columns = 10.24 columns a step: every column swept
        return sim.device("r/lidar").range_image.copy()

    alone, beside = image(False), image(True)
    assert alone.tobytes() == beside.tobytes()
    assert (alone >= WALL_X).all() and np.isfinite(alone).any()     # the wall or nothing, never the housing
