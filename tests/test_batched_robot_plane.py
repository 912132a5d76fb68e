"""A robot's plane part in the batched simulation (raycast/copies.py, CopyRays' robot planes): every
ray kind of every copy sees a sized or unbounded ``plane`` carried by a robot exactly as a single
Simulation does -- camera pixels, range-finder and lidar ranges, distance sensors, recognition --
bit for bit, in FAST and EXACT; never another copy's robot's plane; its own robot's plane as the
single world does (mounted visual rays see it, rays that skip their robot do not)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.raycast.engine import RayEngine, RayKind, ShapeEntry
from sensorium.server.raycast.kinds import Precision
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Plane, Pose
from sensorium.server.world.loader import LoadedWorld

FACING_MINUS_X = [0, 1, 0, -math.pi / 2]     # a plane's front (+z) turned to -x
FACING_PLUS_X = [0, 1, 0, math.pi / 2]
TABLE = [[0, 0, 0], [2, 2, 0]]                # a distance sensor's value: its distance (m), up to 2 m

DEVICES = [
    {"device": "Camera", "name": "cam", "width": 16, "height": 12, "field_of_view": 1.2,
     "recognition": {"occlusion": 1, "segmentation": True}},
    {"device": "RangeFinder", "name": "depth", "width": 9, "height": 7, "field_of_view": 1.0, "max_range": 5.0},
    {"device": "Lidar", "name": "lidar", "horizontal_resolution": 64, "field_of_view": 2.0, "number_of_layers": 3,
     "vertical_field_of_view": 0.3, "max_range": 5.0},
    {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "lookup_table": TABLE},
    {"device": "DistanceSensor", "name": "gen", "lookup_table": TABLE},
    {"device": "DistanceSensor", "name": "wide", "number_of_rays": 5, "aperture": 0.4, "lookup_table": TABLE},
    {"device": "DistanceSensor", "name": "ir_back", "type": "infra-red", "lookup_table": TABLE,
     "pose": {"rotation": [0, 0, 1, math.pi]}},
    {"device": "DistanceSensor", "name": "gen_back", "lookup_table": TABLE, "pose": {"rotation": [0, 0, 1, math.pi]}},
]
DISTANCES = ["ir", "gen", "wide", "ir_back", "gen_back"]


def plane(name: str, at, rotation, size=None, color=(0, 0, 1)) -> dict:
    geometry = {"type": "plane"} if size is None else {"type": "plane", "size": list(size)}
    return {"name": name, "pose": {"translation": list(at), "rotation": list(rotation)}, "geometry": geometry,
            "appearance": {"base_color": list(color)}}


def world(board_shapes=None, eye_shapes=(), solids=None, floor=True) -> wm.World:
    """The robot ``eye`` (every ray device, looking along +x; two sensors looking back) at the origin,
    the robot ``board`` 0.6 m ahead carrying a 0.3 m plate facing it; a wall 2 m ahead, a floor."""
    if board_shapes is None:
        board_shapes = [plane("plate", (0, 0, 0), FACING_MINUS_X, (0.3, 0.3))]
    if solids is None:
        solids = [{"name": "wall", "pose": {"translation": [2.0, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.1, 20, 20]},
                   "appearance": {"base_color": [0.8, 0.5, 0.2]}}]
        if floor:
            solids.append(plane("floor", (0, 0, -0.2), [0, 0, 1, 0], color=(0.3, 0.6, 0.3)))
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 5},
        "solids": solids,
        "lights": [{"type": "DirectionalLight", "direction": [1, 0.2, -1], "intensity": 0.6, "ambient_intensity": 0.4}],
        "robots": [{"name": "eye", "shapes": list(eye_shapes), "devices": DEVICES},
                   {"name": "board", "pose": {"translation": [0.6, 0.0, 0.0]}, "shapes": board_shapes,
                    "recognition_colors": [[1, 0, 0]]}]})


def _batched(w: wm.World, copies: int, precision: str) -> BatchedSimulation:
    return BatchedSimulation(LoadedWorld(world=w, source="<test>", base_dir=Path.cwd()), copies, precision=precision)


def _readings(bs: BatchedSimulation, copy: int) -> dict:
    out = {"cam": bs.image(bs.device("eye", "cam"))[copy], "depth": bs.range_image(bs.device("eye", "depth"))[copy],
           "lidar": bs.range_image(bs.device("eye", "lidar"))[copy],
           "objects": repr(bs.recognition_objects(bs.device("eye", "cam"), copy)),
           "segmentation": bs.segmentation_image(bs.device("eye", "cam"))[copy]}
    out.update({d: bs.value(bs.device("eye", d))[copy] for d in DISTANCES})
    return out


def _single(w: wm.World, precision: str, board_at=None) -> dict:
    sim = Simulation(w, precision=precision)
    if board_at is not None:
        sim.robot("board").set_pose(board_at)
    eye = sim.robot("eye")
    for name in ["cam", "depth", "lidar", *DISTANCES]:
        eye.device(name).enable(16)
    eye.device("cam").recognition_enable(16)
    eye.device("cam").enable_segmentation(True)
    sim.step()
    out = {"cam": eye.device("cam").image, "depth": eye.device("depth").range_image,
           "lidar": eye.device("lidar").range_image, "objects": repr(eye.device("cam").objects),
           "segmentation": eye.device("cam").segmentation_image}
    out.update({d: np.asarray(eye.device(d).value) for d in DISTANCES})
    return out


def _run_batched(w: wm.World, copies: int, precision: str, board_at: dict | None = None) -> BatchedSimulation:
    bs = _batched(w, copies, precision)
    for c, at in (board_at or {}).items():
        bs.set_pose(c, bs.slot("board"), at)
    for name in ["cam", "depth", "lidar", *DISTANCES]:
        bs.enable(bs.device("eye", name), 16)
    bs.recognition_enable(bs.device("eye", "cam"), 16)
    bs.enable_segmentation(bs.device("eye", "cam"), True)
    bs.step()
    return bs


def _assert_same(got: dict, want: dict, where) -> None:
    for key, w in want.items():
        g = got[key]
        if isinstance(w, str):
            assert g == w, (where, key)
        else:
            w, g = np.asarray(w), np.asarray(g)
            assert g.shape == w.shape and g.tobytes() == w.tobytes(), (where, key, g.ravel()[:8], w.ravel()[:8])


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_every_ray_kind_sees_a_robots_sized_plane_as_the_single_world(precision):
    """The bug: a batched camera did not see a plane part of a robot (nor did any batched ray). Now
    every device of every copy reads the single world's values, bit for bit; the plate is seen."""
    w = world()
    want = _single(w, precision)
    bs = _run_batched(w, 3, precision)
    for c in range(3):
        _assert_same(_readings(bs, c), want, c)
    blue = want["cam"][..., 0] > want["cam"][..., 2] + 40          # BGRA: the plate's blue
    assert blue.any(), "the plate is in the camera's view"
    assert "id=2" in want["objects"] and want["segmentation"][..., :3].any()   # the board recognised


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_range_finder_and_a_distance_sensor_read_another_robots_plane_in_closed_form(precision):
    """The plate faces the sensors 0.6 m ahead: the generic distance sensor's ray and the range
    finder's centre pixel meet it at 0.6 m (a sized plane with no box behind it: only the plane); a
    white plate reads the same to the infra-red sensor (its red reflects fully)."""
    white = [plane("plate", (0, 0, 0), FACING_MINUS_X, (0.3, 0.3), (1, 1, 1))]
    bs = _run_batched(world(board_shapes=white, floor=False), 2, precision)
    depth = bs.range_image(bs.device("eye", "depth"))
    for c in range(2):
        assert depth[c][3, 4] == np.float32(0.6)   # (planar depth: 0.6 across the plate)
        assert bs.value(bs.device("eye", "gen"))[c] == pytest.approx(0.6, abs=1e-9)
        assert bs.value(bs.device("eye", "ir"))[c] == pytest.approx(0.6, abs=1e-9)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_copies_never_see_each_others_robot_planes(precision):
    """Copy 1's board stands aside: its sensors see the wall behind where copy 0's plate is, and
    each copy reads the single world with its board where that copy has it."""
    w = world()
    aside = [0.6, 4.0, 0.0]
    bs = _run_batched(w, 3, precision, {1: aside})
    _assert_same(_readings(bs, 0), _single(w, precision), 0)
    _assert_same(_readings(bs, 2), _single(w, precision), 2)
    _assert_same(_readings(bs, 1), _single(w, precision, aside), 1)
    depth = bs.range_image(bs.device("eye", "depth"))
    assert depth[0][3, 4] == np.float32(0.6) and depth[1][3, 4] == pytest.approx(1.95, abs=1e-6)   # (float32 images)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_robots_own_plane_is_seen_by_its_mounted_rays_and_not_by_rays_that_skip_it(precision):
    """The eye carries a plane 0.3 m behind it, facing it: its infra-red sensor looking back (a
    visual ray, mounted: its robot stays visible to it, as in Webots) meets it at 0.3 m; the generic
    one (ODE-style: its own robot skipped) does not -- in both simulations alike."""
    w = world(eye_shapes=[plane("visor", (-0.3, 0, 0), FACING_PLUS_X, (0.2, 0.2), (1, 1, 1))])
    want = _single(w, precision)
    assert float(want["ir_back"]) == pytest.approx(0.3, abs=1e-9) and float(want["gen_back"]) == 2.0
    bs = _run_batched(w, 2, precision)
    for c in range(2):
        _assert_same(_readings(bs, c), want, c)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_unbounded_tilted_robot_planes_and_static_plane_parts(precision):
    """Unbounded robot planes (each copy's own, with several planes per world: the general plane
    pass), a tilted sized plane on a static solid, and a box beside the robot's plane: the single
    world's values in each copy."""
    board = [plane("sheet", (0.4, 0, 0), [0.3, 1, 0.1, -1.3]),
             {"name": "post", "pose": {"translation": [0, 0.3, 0]}, "geometry": {"type": "box", "size": [0.1, 0.1, 0.5]}}]
    solids = [{"name": "panel", "pose": {"translation": [1.2, -0.3, 0.1]},
               "shapes": [plane("face", (0, 0, 0), [0.1, 1, 0, -1.4], (0.6, 0.5), (1, 1, 0))]},
              plane("floor", (0, 0, -0.2), [0, 0, 1, 0], color=(0.3, 0.6, 0.3))]
    w = world(board_shapes=board, solids=solids)
    aside = [0.6, 0.05, 0.0]
    bs = _run_batched(w, 2, precision, {1: aside})
    _assert_same(_readings(bs, 0), _single(w, precision), 0)
    _assert_same(_readings(bs, 1), _single(w, precision, aside), 1)


def test_plane_pass_answers_do_not_depend_on_the_cast():
    """Several planes (the general plane pass): each ray's hit is the same cast alone or among
    others (the plane arithmetic is summed element by element in one order, never by BLAS, so the
    copies' robot planes can be the single world's bit for bit)."""
    eng = RayEngine(Precision.FAST)
    rng = np.random.default_rng(3)
    for k in range(3):
        axis = rng.normal(size=3)
        eng.add_body([ShapeEntry(Plane(size=(2.0, 3.0)), Pose.from_axis_angle(axis, float(rng.uniform(0, 3))),
                                 bounding=True, visual=True)],
                     Pose(np.eye(3), rng.normal(size=3)), owner=k, movable=bool(k))
    O = rng.normal(size=(257, 3))
    D = rng.normal(size=(257, 3))
    D /= np.linalg.norm(D, axis=1)[:, None]
    for kind in (RayKind.VISUAL, RayKind.BOUNDING):
        every = eng.cast(O, D, kind=kind)
        assert np.isfinite(every.distance).sum() > 10
        for i in range(0, 257, 16):
            one = eng.cast(O[i:i + 1], D[i:i + 1], kind=kind)
            assert one.distance.tobytes() == every.distance[i:i + 1].tobytes()
            assert one.normal.tobytes() == every.normal[i:i + 1].tobytes()


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_textured_semi_transparent_robot_plate(precision, tmp_path):
    """A robot's plate with a texture and transparency 0.4: each copy's camera image (texels looked up
    at the copy's pose, the layers behind it cast per copy) is the single world's."""
    from PIL import Image

    Image.new("RGB", (4, 4), (200, 100, 30)).save(tmp_path / "t.png")
    plate = plane("plate", (0, 0, 0), FACING_MINUS_X, (0.3, 0.3), (0.5, 1.0, 1.0))
    plate["appearance"].update(texture="t.png", transparency=0.4)
    w = world(board_shapes=[plate])
    moved = [0.7, 0.05, 0.02]
    bs = BatchedSimulation(LoadedWorld(world=w, source="<test>", base_dir=tmp_path), 2, precision=precision)
    bs.set_pose(1, bs.slot("board"), moved)
    ref = bs.device("eye", "cam")
    bs.enable(ref, 16)
    bs.step()
    for c, at in ((0, None), (1, moved)):
        sim = Simulation(w, precision=precision, base_dir=tmp_path)
        if at is not None:
            sim.robot("board").set_pose(at)
        cam = sim.robot("eye").device("cam")
        cam.enable(16)
        sim.step()
        assert sim.counters.get("texture_lookups", 0) > 0
        assert bs.image(ref)[c].tobytes() == cam.image.tobytes(), c


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_many_poses_of_a_robot_plate_every_copy_its_single_world(precision):
    """Five copies, the board at a scattered pose in each (turned about z: the plate's normal no
    longer along an axis); one Simulation re-posed for each: the same readings, bit for bit."""
    rng = np.random.default_rng(11)
    w = world()
    poses = [([float(rng.uniform(0.4, 1.2)), float(rng.uniform(-0.3, 0.3)), float(rng.uniform(-0.1, 0.1))],
              [0, 0, 1, float(rng.uniform(-1.0, 1.0))]) for _ in range(5)]
    bs = _batched(w, 5, precision)
    for c, (xyz, rotation) in enumerate(poses):
        bs.set_pose(c, bs.slot("board"), xyz, rotation=rotation)
    for name in ["cam", "depth", "lidar", *DISTANCES]:
        bs.enable(bs.device("eye", name), 16)
    bs.recognition_enable(bs.device("eye", "cam"), 16)
    bs.enable_segmentation(bs.device("eye", "cam"), True)
    bs.step()
    sim = Simulation(w, precision=precision)
    eye = sim.robot("eye")
    for name in ["cam", "depth", "lidar", *DISTANCES]:
        eye.device(name).enable(16)
    eye.device("cam").recognition_enable(16)
    eye.device("cam").enable_segmentation(True)
    for c, (xyz, rotation) in enumerate(poses):
        sim.robot("board").set_pose(xyz, rotation=rotation)
        sim.step()
        want = {"cam": eye.device("cam").image, "depth": eye.device("depth").range_image,
                "lidar": eye.device("lidar").range_image, "objects": repr(eye.device("cam").objects),
                "segmentation": eye.device("cam").segmentation_image}
        want.update({d: np.asarray(eye.device(d).value) for d in DISTANCES})
        _assert_same(_readings(bs, c), want, c)


@pytest.mark.parametrize("size", [None, (2.0, 1.5)])
@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_robot_carrying_the_worlds_only_plane_level(precision, size):
    """The world's one plane is a level platform the board carries (the single world then takes its
    one-axis-aligned-plane passes: the C pass, the lidar's floor pass): each copy the same readings."""
    board = [plane("platform", (0, 0, -0.15), [0, 0, 1, 0], size, (0.9, 0.8, 0.7))]
    w = world(board_shapes=board, floor=False)
    lower = [0.6, 0.0, -0.05]
    bs = _run_batched(w, 2, precision, {1: lower})
    _assert_same(_readings(bs, 0), _single(w, precision), 0)
    _assert_same(_readings(bs, 1), _single(w, precision, lower), 1)
    lidar = bs.range_image(bs.device("eye", "lidar"))
    assert np.isfinite(lidar[0]).any() and lidar[0].tobytes() != lidar[1].tobytes()
