"""Bumpers (TouchSensor) and altimeters in the batched simulation and the Gymnasium envs
(sensorium/server/sim/batched_kinematic.py, sensorium/gym/env.py): every copy bit-identical to the
single Simulation with its seed, closed-form readings (a robot pushing against a wall, at rest, at a
known height, a WGS84 GPS at the reference), the single and vector envs observing them alike, and a
force sensor refused; a GPS in a WGS84 world, bit-identical too."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim import batched_kinematic as kin
from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.contact import pieces_touch
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests.test_batched_kinematic import native  # noqa: F401  (the fixture: C helper and math paths)
from tests.test_batched_sim import _enable_both

WORLD = Path(__file__).parent / "worlds" / "bumpers.yaml"
PERIODS = {"a": {"bumper": 16, "altimeter": 32, "plain_altimeter": 16},
           "b": {"bumper": 32, "altimeter": 16},
           "c": {"bumper": 16, "altimeter": 48}}


def _world(seed: int) -> LoadedWorld:
    lw = load_world(WORLD)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _wheels_both(bs: BatchedSimulation, sims: list[Simulation], robot: str, lr: np.ndarray) -> None:
    """Velocity control of every wheel of each side (a skid-steer robot's too) in every copy and its
    Simulation."""
    bs.set_wheels(bs.slot(robot), lr[:, 0], lr[:, 1])
    for c, s in enumerate(sims):
        drive = s.robot(robot).drive
        for side, motors in enumerate((drive.lefts, drive.rights)):
            for m in motors:
                m.set_position(math.inf)
                m.set_velocity(float(lr[c, side]))


def _loaded(w: wm.World) -> LoadedWorld:
    return LoadedWorld(world=w, source="<test>", base_dir=Path.cwd())


def test_every_copy_reads_its_bumpers_and_altimeters_as_the_single_simulation(native):  # noqa: F811
    """Three robots (one skid-steer) between walls, a ball and a ramp, random per-copy wheel commands
    that drive them into the walls, the ball and one another; bumpers at different periods (one with
    a resolution, which a bumper ignores), altimeters with noise, resolution and a tilted, offset
    mount; a supervisor move, a re-enable and a reset with a new seed on the way: after every basic
    step every bumper and altimeter value of every copy equals that of a Simulation built with that
    copy's seed, bit for bit (NaN before the first value included), with the C helper and without it."""
    seeds = [5, 6, 7, 8]
    bs = BatchedSimulation(_world(0), len(seeds))
    bs.reset(np.arange(len(seeds)), seeds)
    sims = [Simulation(_world(s)) for s in seeds]
    for c in range(len(seeds)):
        _enable_both(bs, sims, PERIODS, c)
    rng = np.random.default_rng(2)
    seen = {"pressed": 0, "free": 0, "nan": 0}
    heights: set[float] = set()
    for step in range(240):
        if step % 15 == 0:
            for robot in PERIODS:        # mostly ahead or back, turning a little: into the walls and each other
                ahead, turn = rng.uniform(-14.0, 14.0, (len(seeds), 1)), rng.uniform(-3.0, 3.0, (len(seeds), 1))
                _wheels_both(bs, sims, robot, np.concatenate([ahead - turn, ahead + turn], axis=1))
        if step == 90:                          # a supervisor move onto the ramp in copy 2
            bs.set_pose(2, bs.slot("a"), [-0.4, -0.3, 0.3])
            sims[2].robot("a").set_pose([-0.4, -0.3, 0.3])
        if step == 130:                         # copy 1 as a new world with another seed
            bs.reset([1], [42])
            sims[1] = Simulation(_world(42))
            _enable_both(bs, sims, PERIODS, 1)
        if step == 170:                         # copy 3's bumper and altimeter on new periods
            for n, p in (("bumper", 48), ("altimeter", 32)):
                bs.enable(bs.device("b", n), p, copies=[3])
                sims[3].robot("b").device(n).enable(p)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            assert s.time_ms == bs.time_ms[c]
            for robot, names in PERIODS.items():
                slot = bs.slot(robot)
                assert s.robot(robot).pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c, robot)
                for n in names:
                    want = np.float64(s.robot(robot).device(n).value)
                    got = bs.value(bs.device(robot, n))[c]
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n, want, got)
                seen["nan"] += math.isnan(bs.value(bs.device(robot, "bumper"))[c])
                bumper = s.robot(robot).device("bumper").value
                seen["pressed"] += bumper == 1.0
                seen["free"] += bumper == 0.0
            heights.add(float(bs.value(bs.device("a", "plain_altimeter"))[c]))
    # they pushed against things and drove freely, rode the ramp, and each copy's noise is its own
    # (bumper-pressed copy-steps: 99 since robots on the ramp cover their wheels' distance along it)
    assert seen["pressed"] > 80 and seen["free"] > 1000 and seen["nan"] > 0 and len(heights) > 20
    noisy = bs.value(bs.device("b", "altimeter"))
    assert len({float(v) for v in noisy}) == len(seeds)


SHAPED = Path(__file__).parent / "worlds" / "shaped_bumpers.yaml"
SHAPED_PERIODS = {"a": {"left": 16, "right": 16, "rear": 32}, "b": {"front": 16}, "c": {"nose": 48, "body_bumper": 16}}


def _shaped(seed: int) -> LoadedWorld:
    """The shaped-bumpers world with ``seed`` as its random seed."""
    lw = load_world(SHAPED)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _shaped_engines(seeds: list[int]) -> tuple[BatchedSimulation, list[Simulation]]:
    """That world as one copy per seed (reset with those seeds) and as a Simulation per seed."""
    bs = BatchedSimulation(_shaped(0), len(seeds))
    bs.reset(np.arange(len(seeds)), seeds)
    return bs, [Simulation(_shaped(s)) for s in seeds]


def test_bumpers_with_their_own_shapes_read_in_every_copy_as_the_single_simulation(native):  # noqa: F811
    """Bumpers with bounding shapes of their own (a round robot's left, right and rear boxes, a box
    robot's front bar, a small round nose beside a shapeless bumper), random per-copy wheel commands
    that push the robots into the walls, the ball and one another, stops against them, a supervisor
    move, a reset with a new seed: every bumper value of every copy equals that of a Simulation
    built with that copy's seed, bit for bit, with the C helper and without it; the left and right
    bumpers disagree on some steps (each reads where its robot was hit)."""
    seeds = [5, 6, 7]
    bs, sims = _shaped_engines(seeds)
    for c in range(len(seeds)):
        _enable_both(bs, sims, SHAPED_PERIODS, c)
    # (commands under which robot a is hit on one side often: turning robots are pushed off walls
    # rather than held against them, so some commands leave it pressed on one side only briefly)
    rng = np.random.default_rng(3)
    seen = {"pressed": 0, "free": 0, "one_side": 0}
    for step in range(300):
        if step % 30 == 0:
            for robot in SHAPED_PERIODS:
                ahead, turn = rng.uniform(-14.0, 14.0, (len(seeds), 1)), rng.uniform(-3.0, 3.0, (len(seeds), 1))
                stop = rng.uniform(size=(len(seeds), 1)) < 0.2          # some stand still where they are
                lr = np.where(stop, 0.0, np.concatenate([ahead - turn, ahead + turn], axis=1))
                _wheels_both(bs, sims, robot, lr)
        if step == 70:
            bs.set_pose(2, bs.slot("a"), [0.5, 0.3, 0.0])
            sims[2].robot("a").set_pose([0.5, 0.3, 0.0])
        if step == 120:
            bs.reset([1], [42])
            sims[1] = Simulation(_shaped(42))
            _enable_both(bs, sims, SHAPED_PERIODS, 1)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in SHAPED_PERIODS.items():
                assert s.robot(robot).pose.translation.tobytes() == bs.pos[c, bs.slot(robot)].tobytes(), (step, c, robot)
                for n in names:
                    want = np.float64(s.robot(robot).device(n).value)
                    got = bs.value(bs.device(robot, n))[c]
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n, want, got)
                    seen["pressed"] += want == 1.0
                    seen["free"] += want == 0.0
            left, right = (s.robot("a").device(n).value for n in ("left", "right"))
            seen["one_side"] += left != right and not (math.isnan(left) or math.isnan(right))
    assert seen["pressed"] > 80 and seen["free"] > 1000 and seen["one_side"] > 20, seen


SLOW_PERIODS = {"a": {"left": 48, "right": 64, "rear": 32}, "b": {"front": 80}, "c": {"nose": 48, "body_bumper": 64}}


def test_slow_bumpers_keep_a_touch_until_read_in_every_copy_as_the_single_simulation(native):  # noqa: F811
    """The shaped bumpers read every 32 to 80 ms in a 16 ms world, random per-copy wheel commands
    that push the robots into the walls, the ball and one another and pull them off again, some
    bumpers disabled and enabled again in some copies, a reset with a new seed: every reading of
    every copy equals its Simulation's, bit for bit, with the C helper and without it -- among them
    readings of 1 where the bumper touched only on a step between two readings (or while disabled)
    and no longer touches at the reading's step."""
    seeds = [5, 6, 7, 8]
    bs, sims = _shaped_engines(seeds)
    for c in range(len(seeds)):
        _enable_both(bs, sims, SLOW_PERIODS, c)
    rng = np.random.default_rng(11)
    seen = {"pressed": 0, "latched": 0}
    for step in range(300):
        if step % 10 == 0:               # short pushes: into something and off it within a period
            for robot in SLOW_PERIODS:
                ahead, turn = rng.uniform(-14.0, 14.0, (len(seeds), 1)), rng.uniform(-3.0, 3.0, (len(seeds), 1))
                _wheels_both(bs, sims, robot, np.concatenate([ahead - turn, ahead + turn], axis=1))
        if step in (60, 150):            # some bumpers off in copies 0 and 2 ...
            for robot, n in (("a", "left"), ("b", "front")):
                _enable_both(bs, sims, {robot: {n: 0}}, 0)
                _enable_both(bs, sims, {robot: {n: 0}}, 2)
        if step in (90, 180):            # ... and on again at other periods
            for robot, n, p in (("a", "left", 64), ("b", "front", 32)):
                _enable_both(bs, sims, {robot: {n: p}}, 0)
                _enable_both(bs, sims, {robot: {n: p}}, 2)
        if step == 200:
            bs.reset([3], [42])
            sims[3] = Simulation(_shaped(42))
            _enable_both(bs, sims, SLOW_PERIODS, 3)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in SLOW_PERIODS.items():
                for n in names:
                    dev = s.robot(robot).device(n)
                    want = np.float64(dev.value)
                    got = bs.value(bs.device(robot, n))[c]
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n, want, got)
                    if dev.measured_at_ms == s.time_ms and want == 1.0:
                        seen["pressed"] += 1
                        seen["latched"] += not dev.touching()
    assert seen["pressed"] > 30 and seen["latched"] >= 5, seen


def _placed_shaped(copies: int) -> tuple[BatchedSimulation, np.ndarray]:
    """shaped_bumpers.yaml in ``copies`` copies with its shaped bumpers enabled every step, and
    their columns."""
    bs = BatchedSimulation(load_world(SHAPED), copies)
    bs.reset(np.arange(copies), list(range(copies)))
    for robot, names in SHAPED_PERIODS.items():
        for n in names:
            bs.enable(bs.device(robot, n), 16)
    k = bs.kinematic
    cols = np.array([col for col in range(len(k.bumper_own)) if k.bumper_own[col]])
    return bs, cols


def _touch_everything(bs: BatchedSimulation, c: int, col: int) -> float:
    """contact.pieces_touch of bumper ``col`` of copy ``c`` on every solid and every other robot."""
    k = bs.kinematic
    r = int(k.slot["TouchSensor"][col])
    pieces, _, _ = k._bumper_shapes(col)
    robots = [ob for j, f in enumerate(bs.feet) if f is not None and j != r for ob in k._robot_obstacles(c, j)]
    return 1.0 if pieces_touch(pieces, bs.centres[c, r], float(bs.foot_yaw[c, r]), float(bs.heights[c, r]),
                               bs.contact._obs, robots) else 0.0


def test_shaped_bumpers_read_what_every_pair_would_at_gaps_about_the_tolerance():
    """Robot a's left bumper put 0, 0.5e-6, 0.99e-6, 1.01e-6, 2e-6, 1e-3 m and 0.05 m (and 1e-6 m
    into it) from the east wall, turned, and the box robot b's bar as far from robot a, in 512
    copies: every shaped bumper of every copy reads what contact.pieces_touch gives on every solid
    and robot of its copy (the broad phase drops no touching pair), and the left bumper reads 1 up
    to the 1e-6 m tolerance and 0 beyond."""
    bs, cols = _placed_shaped(512)
    rng = np.random.default_rng(9)
    gaps = np.array([-1e-6, 0.0, 0.5e-6, 0.99e-6, 1.01e-6, 2e-6, 1e-3, 0.05])
    a, b = bs.slot("a"), bs.slot("b")
    left = next(col for col in cols.tolist() if int(bs.kinematic.slot["TouchSensor"][col]) == a
                and bs.kinematic.bumper_own[col][0][1].translation[1] > 0.0)
    pieces, _, _ = bs.kinematic._bumper_shapes(left)
    east = 0.85                                     # the east wall's west face (x = 0.9 - 0.05)
    want_left = np.full(512, np.nan)
    for c in range(512):
        yaw = float(rng.uniform(-0.6, 0.2))
        shape = pieces[0].points @ np.array([[math.cos(yaw), math.sin(yaw)], [-math.sin(yaw), math.cos(yaw)]])
        reach = float(np.max(shape[:, 0])) + pieces[0].round
        gap = float(gaps[c % len(gaps)])
        bs.centres[c, a] = [east - reach - gap, float(rng.uniform(-0.3, 0.3))]
        bs.foot_yaw[c, a] = yaw
        # robot b: its bar's front toward robot a's body in some copies, elsewhere far off
        bs.centres[c, b] = [float(rng.uniform(-0.6, 0.2)), float(rng.uniform(-0.6, 0.6))]
        bs.foot_yaw[c, b] = float(rng.uniform(-math.pi, math.pi))
        if abs(gap) < 1e-3:
            want_left[c] = 1.0 if gap <= 1e-6 - 1e-9 else (0.0 if gap >= 1e-6 + 1e-9 else np.nan)
        elif gap > 2e-6:
            want_left[c] = np.nan                     # robot b may touch it: no closed form
    copies = np.repeat(np.arange(512), len(cols))
    got = bs.kinematic._bumper(copies, np.tile(cols, 512)).reshape(512, len(cols))
    for c in range(512):
        for m, col in enumerate(cols.tolist()):
            assert got[c, m] == _touch_everything(bs, c, col), (c, col)
    m = cols.tolist().index(left)
    sure = ~np.isnan(want_left)
    assert np.array_equal(got[sure, m], want_left[sure])
    assert got[:, :].sum() > 100 and (got == 0.0).sum() > 1000


def test_shaped_bumpers_test_closely_only_the_copies_near_something(monkeypatch):
    """64 copies with every robot in the middle of the arena, far from the walls, the ball and one
    another, but copy 5's robot a turned 0.3 rad left with its right bumper (then its foremost) on
    the east wall: only copy 5's bumpers run contact.pieces_touch (the others are out of reach in
    the broad phase); its right bumper reads 1, every other 0."""
    bs, cols = _placed_shaped(64)
    a, b, c_ = bs.slot("a"), bs.slot("b"), bs.slot("c")
    bs.centres[:, a] = [-0.35, 0.0]
    bs.centres[:, b] = [0.35, 0.0]
    bs.centres[:, c_] = [0.0, 0.4]
    bs.foot_yaw[:, [a, b, c_]] = 0.0
    k = bs.kinematic
    right = next(col for col in cols.tolist() if int(k.slot["TouchSensor"][col]) == a
                 and k.bumper_own[col][0][1].translation[1] < 0.0)
    pieces, _, _ = k._bumper_shapes(right)
    yaw = 0.3
    shape = pieces[0].points @ np.array([[math.cos(yaw), math.sin(yaw)], [-math.sin(yaw), math.cos(yaw)]])
    bs.centres[5, a] = [0.85 - float(np.max(shape[:, 0])) - pieces[0].round, 0.0]
    bs.foot_yaw[5, a] = yaw
    seen: list = []
    real = kin.pieces_touch

    def counted(pieces, centre, *rest):
        seen.append(centre.tobytes())
        return real(pieces, centre, *rest)
    monkeypatch.setattr(kin, "pieces_touch", counted)
    copies = np.repeat(np.arange(64), len(cols))
    got = k._bumper(copies, np.tile(cols, 64)).reshape(64, len(cols))
    assert seen and set(seen) == {bs.centres[5, a].tobytes()}
    want = np.zeros((64, len(cols)))
    want[5, cols.tolist().index(right)] = 1.0
    assert np.array_equal(got, want), got[5]


def _walled(z: float = 0.05, wgs84: bool = False) -> wm.World:
    """A robot facing a wall 0.5 m ahead on a flat floor (no ramp), a bumper and an altimeter 4 cm
    above its origin."""
    info: dict = {"basic_time_step": 16, "gps_reference": [46.5, 6.6, 400.0] if wgs84 else [0.0, 0.0, 0.0]}
    if wgs84:
        info["gps_coordinate_system"] = "WGS84"
    return wm.World.model_validate({
        "world_info": info,
        "solids": [{"name": "wall", "pose": {"translation": [0.6, 0.0, 0.25]},
                    "geometry": {"type": "box", "size": [0.1, 2.0, 0.5]}}],
        "robots": [{"name": "bot", "pose": {"translation": [0.0, 0.0, z]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.05, "height": 0.05}},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": [{"device": "TouchSensor", "name": "bumper"},
                                {"device": "Altimeter", "name": "altimeter",
                                 "pose": {"translation": [0.01, 0.0, 0.04]}}]}]})


def test_a_robot_driven_into_a_wall_reads_its_bumper_while_pushing_and_its_height():
    """At rest the bumper reads 0 and the altimeter its mount's height, 0.25 + 0.04 (0.05 + 0.04
    in the other copy); driven at 0.5 m/s into a wall whose face is 0.55 m ahead, a robot of radius
    5 cm reaches it after 0.5 m (1 s): the bumper reads 0 on the way, 1 on every step it pushes
    (its move clipped at x = 0.5), 0 again once the wheels stop and while it backs off. A WGS84
    world adds its reference altitude (400 m) to the height."""
    for wgs84, offset in ((False, 0.0), (True, 400.0)):
        bs = BatchedSimulation(_loaded(_walled(wgs84=wgs84)), 2)
        bs.set_pose(0, 0, [0.0, 0.0, 0.25])
        bump, alt = bs.device("bot", "bumper"), bs.device("bot", "altimeter")
        bs.enable(bump, 16)
        bs.enable(alt, 16)
        bs.step()
        assert bs.value(bump).tolist() == [0.0, 0.0]
        assert bs.value(alt).tolist() == [0.25 + 0.04 + offset, 0.05 + 0.04 + offset]
        bs.set_wheels(0, np.full(2, 10.0), np.full(2, 10.0))      # 10 rad/s on 5 cm wheels: 0.5 m/s
        readings = []
        for _ in range(80):
            bs.step()
            readings.append(bs.value(bump).copy())
        pressed = [k for k, r in enumerate(readings) if r[0] == 1.0]
        assert all((r[0] == r[1]) for r in readings)
        # 0.5 m at 8 mm per step: 62 free steps (0.496 m), the 63rd reaches the wall and is clipped
        assert pressed == list(range(62, 80)) and bs.pos[:, 0, 0].tolist() == pytest.approx([0.5, 0.5], abs=1e-9)
        bs.set_wheels(0, np.zeros(2), np.zeros(2))
        bs.step()
        assert bs.value(bump).tolist() == [0.0, 0.0]               # stopped against the wall
        bs.set_wheels(0, np.full(2, -10.0), np.full(2, -10.0))
        for _ in range(5):
            bs.step()
            assert bs.value(bump).tolist() == [0.0, 0.0]           # backing off
        sim = Simulation(_loaded(_walled(wgs84=wgs84)))            # the single model agrees at rest
        dev = sim.robot("bot").device("altimeter")
        dev.enable(16)
        sim.step()
        assert dev.value == 0.05 + 0.04 + offset


def _wgs84(seed: int, reference: tuple[float, float, float]) -> LoadedWorld:
    lw = _world(seed)
    info = lw.world.world_info.model_copy(update={"gps_coordinate_system": "WGS84", "gps_reference": reference})
    return LoadedWorld(world=lw.world.model_copy(update={"world_info": info}), source=lw.source, base_dir=lw.base_dir)


@pytest.mark.parametrize("reference", [(46.5, 6.6, 400.0), (-33.9, 151.2, 20.0), (0.0, -179.99, -5.0)])
def test_every_copy_reads_its_wgs84_gps_as_the_single_simulation(native, reference):  # noqa: F811
    """A WGS84 world (north and south of the equator, at the antimeridian): the robots driving into
    walls and one another with noisy, correlated, quantised and plain GPS and the altimeters; after
    every step every GPS's latitude / longitude / altitude, speed and speed vector and every
    altimeter of every copy equal a Simulation's with that copy's seed, bit for bit, with the C
    helper and without it."""
    seeds = [11, 12, 13]
    bs = BatchedSimulation(_wgs84(0, reference), len(seeds))
    bs.reset(np.arange(len(seeds)), seeds)
    sims = [Simulation(_wgs84(s, reference)) for s in seeds]
    periods = {"a": {"gps": 32, "plain_gps": 16, "altimeter": 16}, "b": {"gps": 16, "altimeter": 48}}
    for c in range(len(seeds)):
        _enable_both(bs, sims, periods, c)
    rng = np.random.default_rng(9)
    for step in range(100):
        if step % 20 == 0:
            for robot in periods:
                ahead, turn = rng.uniform(-14.0, 14.0, (len(seeds), 1)), rng.uniform(-3.0, 3.0, (len(seeds), 1))
                _wheels_both(bs, sims, robot, np.concatenate([ahead - turn, ahead + turn], axis=1))
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in periods.items():
                for n in names:
                    ref, dev = bs.device(robot, n), s.robot(robot).device(n)
                    for what in ("value",) if ref.kind == "Altimeter" else ("values", "speed", "speed_vector"):
                        want = np.asarray(getattr(dev, what), dtype=np.float64)
                        assert want.tobytes() == bs.reading(ref, what)[c].tobytes(), (step, c, robot, n, what)
    lat_lon = bs.value(bs.device("a", "plain_gps"))[:, :2]
    assert (np.abs(lat_lon - reference[:2]) < 1e-4).all() and (bs.value(bs.device("a", "gps"))[:, 2] > reference[2]).all()


def test_a_wgs84_gps_at_the_reference_reads_the_reference():
    """A GPS at the world's origin reads the reference latitude and longitude (to the inverse UTM
    series' round trip, < 1e-8° here) and its altitude exactly; 100 m east and 200 m north of it
    (copy 1) the single model's forward projection of its reading is the reference's UTM east + 100 m
    and north + 200 m (to 1 mm); the single simulation reads the same bits."""
    from sensorium.server.devices.gps import Utm

    w = _walled(wgs84=True)
    robot = w.robots[0].model_copy(update={"devices": [
        wm.GPS.model_validate({"device": "GPS", "name": "gps", "pose": {"translation": [0.0, 0.0, -0.05]}})]})
    loaded = _loaded(w.model_copy(update={"robots": [robot], "solids": []}))
    bs = BatchedSimulation(loaded, 2)
    bs.set_pose(1, 0, [100.0, 200.0, 0.05])
    gps = bs.device("bot", "gps")
    bs.enable(gps, 16)
    bs.step()
    got = bs.value(gps)
    assert abs(got[0, 0] - 46.5) < 1e-8 and abs(got[0, 1] - 6.6) < 1e-8 and got[0, 2] == 400.0
    utm = Utm(46.5, 6.6)
    north, east = utm.north_east(46.5, 6.6)
    n1, e1 = utm.north_east(float(got[1, 0]), float(got[1, 1]))
    assert abs(e1 - (east + 100.0)) < 1e-3 and abs(n1 - (north + 200.0)) < 1e-3 and got[1, 2] == 400.0
    sim = Simulation(loaded)
    dev = sim.robot("bot").device("gps")
    dev.enable(16)
    sim.step()
    assert dev.values.tobytes() == got[0].tobytes()


def test_the_batched_simulation_refuses_a_force_sensor_in_one_line():
    bs = BatchedSimulation(_world(0), 1)
    with pytest.raises(BatchedError) as e:
        bs.device("c", "force")
    assert str(e.value) == ("c/force: a force TouchSensor reads NaN without physics; the batched simulation "
                            "measures bumpers only (use Simulation)")


gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402
from tests.test_gym_vector import _reset_both, _step_both  # noqa: E402

OBSERVED = {"bumper": 16, "altimeter": 32, "plain_altimeter": 16}


def _task(observations=None) -> Task:
    return Task(robot="a", observations=OBSERVED if observations is None else observations, control_period_ms=32,
                max_steps=40)


def test_the_envs_observe_bumpers_and_altimeters_alike_and_pass_the_checker():
    """A bumper is a float32 (1,) box [0, 1], an altimeter a float32 (1,) box of the world's ±100 km
    about the reference altitude (the local gps_reference's up value, 30 m, as the altimeter adds it); every sub-env of the vector env equals the single env (rebuilt Simulation, and the
    one-copy batched engine) with its seed, observations and info bit for bit, across autoresets, with
    full-speed runs into the walls (the bumper reads 1 in some of them); both envs pass Gymnasium's
    checker without a warning."""
    n = 3
    venv = SensoriumVectorEnv(WORLD, _task(), n)
    space = venv.single_observation_space
    assert {k: space[k].shape for k in OBSERVED} == dict.fromkeys(OBSERVED, (1,))
    assert (space["bumper"].low.tolist(), space["bumper"].high.tolist()) == ([0.0], [1.0])
    assert (space["altimeter"].low.tolist(), space["altimeter"].high.tolist()) == ([-1e5 + 30.0], [1e5 + 30.0])
    singles = [SensoriumEnv(WORLD, _task(), engine=e) for e in ("simulation", "batched", "simulation")]
    assert [e.engine for e in singles] == ["simulation", "batched", "simulation"]
    obs = _reset_both(venv, singles, 4)
    assert obs["bumper"].tolist() == [[0.0]] * n
    rng = np.random.default_rng(5)
    done = np.zeros(n, dtype=bool)
    ended = pressed = 0
    for t in range(120):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        if t % 20 < 12:
            a[:] = 1.0                                             # full speed ahead: into a wall
        resets, vobs = _step_both(venv, singles, a, done, t)
        ended += resets
        pressed += int((vobs["bumper"] == 1.0).sum())
    assert ended >= n and pressed > 10
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(venv.sub_env(1), skip_render_check=True)
        check_env(SensoriumEnv(WORLD, _task()), skip_render_check=True)
        check_env(SensoriumVectorEnv(WORLD, _task(), 2, flatten=True).sub_env(0), skip_render_check=True)
    venv.close()


def test_a_force_sensor_is_not_an_observation():
    """Named in a task, a force TouchSensor is refused in one line by both envs (it reads NaN
    without physics); by default it is left out while the bumpers and altimeters are observed."""
    want = ("task observation 'force': robot 'c''s force is a force TouchSensor, which reads NaN without physics "
            "(only a bumper is an observation)")
    for make in (lambda t: SensoriumEnv(WORLD, t), lambda t: SensoriumVectorEnv(WORLD, t, 2)):
        with pytest.raises(ValueError) as e:
            make(Task(robot="c", observations=["bumper", "force"]))
        assert str(e.value) == want
        env = make(Task(robot="c"))
        assert sorted(env.single_observation_space.spaces if hasattr(env, "single_observation_space")
                      else env.observation_space.spaces) == ["altimeter", "bumper"]


def test_the_parallel_env_observes_every_robots_bumper_on_both_engines():
    """Every robot of the bumpers world an agent with the default observations (bumpers and
    altimeters; robot c's force sensor left out): the batched engine ("auto" picks it) and the rebuilt
    Simulation give the same observations, rewards and flags, bit for bit, full speed into the walls
    and one another, some bumpers reading 1; PettingZoo's API test passes."""
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test

    from sensorium.gym import SensoriumParallelEnv
    from tests.test_gym_vector import _same_obs

    def make(engine):
        return SensoriumParallelEnv(WORLD, {r: Task(robot=r, control_period_ms=32, max_steps=60) for r in "abc"},
                                    engine=engine)

    batched, rebuilt = make("auto"), make("simulation")
    assert batched._batched is not None and sorted(batched.observation_spaces["c"].spaces) == ["altimeter", "bumper"]
    parallel_api_test(make("auto"), num_cycles=20)
    rng = np.random.default_rng(7)
    ob, _ = batched.reset(seed=3)
    orr, _ = rebuilt.reset(seed=3)
    pressed = 0
    while batched.agents:
        assert batched.agents == rebuilt.agents and all(_same_obs(ob[a], orr[a]) for a in batched.agents)
        pressed += sum(int(ob[a]["bumper"][0] == 1.0) for a in batched.agents)
        acts = {a: (np.ones(2) if rng.random() < 0.7 else rng.uniform(-1, 1, 2)).astype(np.float32)
                for a in batched.agents}
        ob, rb, tb, trb, _ = batched.step(acts)
        orr, rr, tr_, trr, _ = rebuilt.step(acts)
        assert (rb, tb, trb) == (rr, tr_, trr)
    assert pressed > 10
