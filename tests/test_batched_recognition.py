"""Camera recognition and segmentation in the batched simulation (sim/batched_recognition.py): every
copy's recognised objects and segmentation images equal to the single Simulation's with its seed
(occlusion 0, 1 and 2, max_objects, a housed camera, a recognisable robot driving in view, a reset on
the way), copies blind to each other's robots, a copy's view reading them, and the one-line refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensorium.gym.views import CopyRobot
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests.test_batched_sim import _wheels_both

WORLD = Path(__file__).parent / "worlds" / "recognition.yaml"
# {robot: {camera: (recognition period ms, segmentation)}}
CAMERAS = {"rover": {"eye": (16, True), "wide": (32, True), "housed": (48, False)}, "scout": {"dome": (16, True)}}
SCOUT_BGRA = (179, 51, 204, 255)       # floor(255 * (0.8, 0.2, 0.7) + 0.5), blue first


def _world(seed: int) -> LoadedWorld:
    lw = load_world(WORLD)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _enable(bs: BatchedSimulation, sims: list[Simulation], copy: int) -> None:
    for robot, cams in CAMERAS.items():
        for name, (period, segment) in cams.items():
            ref = bs.device(robot, name)
            cam = sims[copy].robot(robot).device(name)
            bs.recognition_enable(ref, period, copies=[copy])
            cam.recognition_enable(period)
            if segment:
                bs.enable_segmentation(ref, True, copies=[copy])
                cam.enable_segmentation(True)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_every_copy_recognises_as_the_single_simulation(precision: str):
    """Both robots driving with random per-copy wheel commands for 90 steps, copy 1 reset with a new
    seed at step 40 and copy 2's recognition of "eye" switched off at step 60: after every step every
    camera's objects (ids, positions, orientations, sizes, places on the image, colours, models) and
    segmentation image in every copy equal the Simulation's built with that copy's seed, bit for bit."""
    seeds = [5, 6, 7]
    bs = BatchedSimulation(_world(0), len(seeds), precision=precision)
    bs.reset(np.arange(len(seeds)), seeds)
    sims = [Simulation(_world(s), precision=precision) for s in seeds]
    for c in range(len(seeds)):
        _enable(bs, sims, c)
    rng = np.random.default_rng(2)
    seen: dict[str, set] = {"ids": set(), "colours": set()}
    differ = 0
    for step in range(90):
        if step % 10 == 0:
            for robot in CAMERAS:
                vmax = 0.4 * float(bs.max_wheel[bs.slot(robot), 0])
                _wheels_both(bs, sims, robot, rng.uniform(-vmax, vmax, (len(seeds), 2)))
        if step == 40:
            bs.reset([1], [42])
            sims[1] = Simulation(_world(42), precision=precision)
            _enable(bs, sims, 1)
            assert not bs.segmentation_image(bs.device("rover", "eye"))[1, :, :, :3].any()   # black again
        if step == 60:
            bs.recognition_enable(bs.device("rover", "eye"), 0, copies=[2])
            sims[2].robot("rover").device("eye").recognition_enable(0)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, cams in CAMERAS.items():
                for name in cams:
                    ref = bs.device(robot, name)
                    cam = s.robot(robot).device(name)
                    got = bs.recognition_objects(ref, c)
                    assert got == cam.objects, (step, c, robot, name)
                    seg = bs.segmentation_image(ref)[c]
                    assert seg.tobytes() == cam.segmentation_image.tobytes(), (step, c, robot, name)
                    seen["ids"] |= {o.id for o in got}
                    seen["colours"] |= {tuple(p) for p in np.unique(seg.reshape(-1, 4), axis=0).tolist()}
        eye = bs.device("rover", "eye")
        differ += len({repr(bs.recognition_objects(eye, c)) for c in range(len(seeds))}) > 1
    assert seen["ids"] == {1, 2, 5, 6}           # both robots (each in the other's view), the crate and the ball
    assert SCOUT_BGRA in seen["colours"] and (0, 0, 0, 255) in seen["colours"]
    assert differ > 10                           # the copies drive apart
    assert bs.recognition_objects(bs.device("rover", "eye"), 2) == sims[2].robot("rover").device("eye").objects


def test_copies_never_see_each_others_robots():
    """The scout in view of the rover's eye in copy 0 and moved far behind it in copy 1: copy 0
    recognises it and paints its colour, copy 1 (its own scout gone from view, copy 0's at the same
    place) neither recognises nor paints it, and the crate's colour is the same in both."""
    bs = BatchedSimulation(_world(3), 2)
    bs.set_pose(1, bs.slot("scout"), translation=[-2.0, 0.0, 0.0])
    eye = bs.device("rover", "eye")
    bs.recognition_enable(eye, 16)
    bs.enable_segmentation(eye, True)
    bs.step()
    ids = [{o.id for o in bs.recognition_objects(eye, c)} for c in range(2)]
    assert 2 in ids[0] and 2 not in ids[1] and 5 in ids[0] & ids[1]
    seg = bs.segmentation_image(eye)
    scout = [(seg[c] == SCOUT_BGRA).all(axis=-1).sum() for c in range(2)]
    assert scout[0] > 20 and scout[1] == 0
    crate = (26, 77, 230, 255)                 # floor(255 * (0.9, 0.3, 0.1) + 0.5), blue first
    assert (seg[0] == crate).all(axis=-1).any() and (seg[1] == crate).all(axis=-1).any()


def test_a_copys_view_reads_its_own_recognition():
    """A task callable's view of copy 1 enables, reads and resets that copy's recognition alone."""
    bs = BatchedSimulation(_world(3), 2)
    bs.set_pose(0, bs.slot("scout"), translation=[-2.0, 0.0, 0.0])
    cam = CopyRobot(bs, 1, bs.slot("rover")).device("eye")
    cam.recognition_enable(16)
    cam.enable_segmentation(True)
    bs.step()
    eye = bs.device("rover", "eye")
    assert bs.recognition_objects(eye, 0) == [] and not bs.segmentation_image(eye)[0, :, :, :3].any()
    assert cam.recognition_objects == cam.objects == bs.recognition_objects(eye, 1)
    assert 2 in {o.id for o in cam.recognition_objects}
    assert (cam.segmentation_image == SCOUT_BGRA).all(axis=-1).any()
    bs.reset([1], [3])
    assert cam.recognition_objects == [] and not cam.segmentation_image[:, :, :3].any()
    bs.step()
    assert cam.recognition_objects == []         # the reset disabled it, as a freshly built world


def test_refusals_are_one_clear_line():
    bs = BatchedSimulation(_world(3), 2)
    eye = bs.device("rover", "eye")
    with pytest.raises(ValueError, match="needs the recognition enabled first"):
        bs.enable_segmentation(eye, True)
    with pytest.raises(ValueError, match="rover/housed: .*no segmentation"):
        bs.recognition_enable(bs.device("rover", "housed"), 16)
        bs.enable_segmentation(bs.device("rover", "housed"), True)
    with pytest.raises(ValueError, match="sampling period must be"):
        bs.recognition_enable(eye, -1)
    with pytest.raises(ValueError, match="enabled per copy"):
        bs.template(eye).recognition_enable(16)
    with pytest.raises(ValueError, match="exposure"):
        bs.template(eye).set_exposure(2.0)
