"""Camera recognition and segmentation in the batched simulation (sim/batched_recognition.py): every
copy's recognised objects and segmentation images equal to the single Simulation's with its seed
(occlusion 0, 1 and 2, max_objects, a housed camera behind a post of its robot, a recognisable robot driving in view, a reset on
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
CAMERAS = {"rover": {"eye": (16, True), "wide": (32, True), "housed": (48, True)}, "scout": {"dome": (16, False)}}
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
                    seen.setdefault(name, set()).update(o.id for o in got)
                    seen["colours"] |= {tuple(p) for p in np.unique(seg.reshape(-1, 4), axis=0).tolist()}
        eye = bs.device("rover", "eye")
        differ += len({repr(bs.recognition_objects(eye, c)) for c in range(len(seeds))}) > 1
    assert seen["ids"] == {1, 2, 5, 6, 7}        # both robots (each in the other's view), the crate, the ball, the box
    assert 7 in seen["housed"] and 7 not in seen["eye"] | seen["wide"]   # occlusion 0 lists the box behind the wall
    assert SCOUT_BGRA in seen["colours"] and (0, 0, 0, 255) in seen["colours"]
    assert differ > 10                           # the copies drive apart
    assert bs.recognition.devices[bs.device("rover", "housed").column].own is not None   # its post met apart
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
    dome = bs.device("scout", "dome")
    bs.recognition_enable(dome, 16)
    with pytest.raises(ValueError, match="^scout/dome: this camera's Recognition node has no segmentation"):
        bs.enable_segmentation(dome, True)
    with pytest.raises(ValueError, match="^rover/plain: this camera has no Recognition node$"):
        bs.recognition_enable(bs.device("rover", "plain"), 16)
    with pytest.raises(ValueError, match="sampling period must be"):
        bs.recognition_enable(eye, -1)
    with pytest.raises(ValueError, match="enabled per copy"):
        bs.template(eye).recognition_enable(16)
    with pytest.raises(ValueError, match="exposure"):
        bs.template(eye).set_exposure(2.0)


gym = pytest.importorskip("gymnasium")

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402
from tests.test_gym_vector import _reset_both, _step_both  # noqa: E402

OBSERVED = {"eye/segmentation": 32, "eye": 32, "wide/segmentation": 64}


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_the_envs_observe_segmentation_images(precision: str):
    """A task naming "<camera>/segmentation": a uint8 (height, width, 3) RGB box of the segmentation
    image beside the camera's own image; every vector sub-env equals the single env (rebuilt
    Simulation, and the one-copy batched engine) with its seed, bit for bit, across autoresets, and
    the scout's colour is observed."""
    task = Task(robot="rover", observations=OBSERVED, control_period_ms=32, max_steps=12)
    world = _world(3)
    n = 3
    venv = SensoriumVectorEnv(world, task, n, precision=precision)
    space = venv.single_observation_space
    assert space["eye/segmentation"].shape == (24, 32, 3) and space["eye/segmentation"].dtype == np.uint8
    assert space["wide/segmentation"].shape == (12, 24, 3)
    singles = [SensoriumEnv(world, task, precision=precision, engine=e) for e in ("simulation", "auto", "simulation")]
    assert [e.engine for e in singles] == ["simulation", "batched", "simulation"]
    obs = _reset_both(venv, singles, 4)
    assert (obs["eye/segmentation"][0] == SCOUT_BGRA[2::-1]).all(axis=-1).any()
    rng = np.random.default_rng(5)
    done = np.zeros(n, dtype=bool)
    ended = 0
    for t in range(30):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        resets, vobs = _step_both(venv, singles, a, done, t)
        ended += resets
        assert all(space[k].contains(vobs[k][0]) for k in OBSERVED)
    assert ended >= n
    venv.close()


def test_a_segmentation_observation_needs_a_segmenting_camera():
    for name, why in (("plain/segmentation", "camera 'plain' has no Recognition node with segmentation: true"),
                      ("nose/segmentation", "robot 'rover' has no camera 'nose'")):
        with pytest.raises(ValueError, match=f"^task observation '{name}': {why}"):
            SensoriumEnv(_world(3), Task(robot="rover", observations=[name]))


def _see_robots(sim, robot, rng) -> None:
    robot.device("eye").recognition_enable(32)


def test_task_callables_read_recognition_objects_on_both_engines():
    """A task enabling recognition in ``start`` and rewarding what the camera recognises (the
    recognised ids summed, plus the first object's depth): the vector env's per-copy views give every
    sub-env the single env's rewards (rebuilt Simulation, one-copy batched engine), bit for bit, across
    autoresets; the scout is seen."""
    given: list[float] = []

    def robots_seen(sim, robot, obs) -> float:
        objs = robot.device("eye").recognition_objects
        given.append(float(sum(o.id for o in objs)) + (objs[0].position[0] if objs else 0.0))
        return given[-1]

    task = Task(robot="rover", observations={"eye/segmentation": 32}, control_period_ms=32, max_steps=10,
                start=_see_robots, reward=robots_seen)
    world = _world(3)
    venv = SensoriumVectorEnv(world, task, 2)
    singles = [SensoriumEnv(world, task, engine=e) for e in ("simulation", "auto")]
    assert [e.engine for e in singles] == ["simulation", "batched"]
    _reset_both(venv, singles, 9)
    rng = np.random.default_rng(6)
    done = np.zeros(2, dtype=bool)
    ended = 0
    for t in range(25):
        ended += _step_both(venv, singles, rng.uniform(-1, 1, (2, 2)).astype(np.float32), done, t)[0]
    assert ended >= 2
    assert any(r >= 2.0 for r in given) and len(set(given)) > 5      # the scout (id 2) seen, rewards vary
    venv.close()
