"""sensorium.server.sim.batched: N copies of a world in one simulation, each bit-identical to the
single Simulation with its seed, never seeing the others."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.raycast import packets
from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world

EPUCK = ["ls0", "ls1", *[f"ps{i}" for i in range(8)]]
SCOUT = ["lidar", "sonar_front", "sonar_left", "sonar_right", "sonar_back"]


def arena(seed: int) -> LoadedWorld:
    lw = load_world(default_world_path())
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _same_value(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


def _wheels_both(bs, sims, robot: str, lr: np.ndarray) -> None:
    slot = bs.slot(robot)
    bs.set_wheels(slot, lr[:, 0], lr[:, 1])
    for c, s in enumerate(sims):
        for m in s.robot(robot).motors.values():
            m.set_position(math.inf)
        s.robot(robot).drive.left.set_velocity(float(lr[c, 0]))
        s.robot(robot).drive.right.set_velocity(float(lr[c, 1]))


def _enable_both(bs, sims, periods: dict, copy: int) -> None:
    """Every device of ``periods`` ({robot: {device: ms}}) enabled in one copy and in its Simulation."""
    for robot, names in periods.items():
        for n, p in names.items():
            bs.enable(bs.device(robot, n), p, copies=[copy])
            sims[copy].robot(robot).device(n).enable(p)


def _same_bits(a, b) -> bool:
    return np.asarray(a, dtype=np.float64).tobytes() == np.asarray(b, dtype=np.float64).tobytes()


def _assert_same(bs, sims, step, robots=(("epuck", EPUCK), ("scout", SCOUT))) -> None:
    """Every copy's clock, poses, values and range images are its Simulation's, bit for bit, for the
    devices ``robots`` names ((robot, [device, ...]), ...)."""
    for c, s in enumerate(sims):
        assert bs.time_ms[c] == s.time_ms
        for robot, names in robots:
            slot = bs.slot(robot)
            pose = s.robot(robot).pose
            assert pose.rotation.tobytes() == bs.rot[c, slot].tobytes(), (step, c, robot)
            assert pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c, robot)
            for n in names:
                ref, dev = bs.device(robot, n), s.robot(robot).device(n)
                if ref.kind == "Lidar":
                    assert dev.range_image.tobytes() == bs.range_image(ref)[c].tobytes(), (step, c, n)
                elif ref.kind == "GPS":
                    for what in ("values", "speed", "speed_vector"):
                        assert _same_bits(getattr(dev, what), bs.reading(ref, what)[c]), (step, c, n, what)
                elif ref.kind == "InertialUnit":
                    for what in ("roll_pitch_yaw", "quaternion"):
                        assert _same_bits(getattr(dev, what), bs.reading(ref, what)[c]), (step, c, n, what)
                elif ref.kind in ("Compass", "Gyro", "Accelerometer"):
                    assert _same_bits(dev.values, bs.value(ref)[c]), (step, c, n)
                else:
                    assert _same_bits(dev.value, bs.value(ref)[c]), (step, c, n, dev.value)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_every_copy_is_the_single_simulation_with_its_seed(precision):
    """Both robots drive (into walls, at each other); every observable device of both is enabled
    (different periods); after every basic step each copy's poses, clock, values and range images
    equal those of a Simulation built with that copy's seed, bit for bit."""
    seeds = [11, 12, 13]
    bs = BatchedSimulation(arena(0), len(seeds), precision=precision)
    bs.reset(np.arange(3), seeds)
    sims = [Simulation(arena(s), precision=precision) for s in seeds]
    periods = {"ls0": 64, "ls1": 32, "lidar": 64, "ps3": 96}
    for robot, names in (("epuck", EPUCK), ("scout", SCOUT)):
        for n in names:
            bs.enable(bs.device(robot, n), periods.get(n, 32))
            for s in sims:
                s.robot(robot).device(n).enable(periods.get(n, 32))
    rng = np.random.default_rng(0)
    for step in range(48):
        if step % 4 == 0:
            for robot in ("epuck", "scout"):
                vmax = float(bs.max_wheel[bs.slot(robot), 0])
                _wheels_both(bs, sims, robot, rng.uniform(-vmax, vmax, (3, 2)) if step % 16
                             else np.full((3, 2), 0.9 * vmax))
        bs.step()
        for s in sims:
            s.step()
        _assert_same(bs, sims, step)
    # the copies differ from one another (own noise streams), and the IR noise was drawn
    ps = bs.value(bs.device("epuck", "ps0"))
    assert len(set(ps.tolist())) == 3


def test_a_robot_in_one_copy_is_invisible_to_the_others_sensors_and_contact():
    """Copy 3's scout stands right in front of the e-puck; in every other copy it stays where the
    world file puts it. Copy 3's e-puck sees it (infra-red) and is stopped by it (contact); copy
    4's e-puck, on the same spot with the same commands, reads exactly what a single simulation
    without the scout there reads, and drives through where copy 3's scout is."""
    n = 6
    bs = BatchedSimulation(arena(5), n, precision="exact")
    bs.reset(np.arange(n), [5] * n)
    epuck, scout = bs.slot("epuck"), bs.slot("scout")
    for c in range(n):
        bs.set_pose(c, epuck, [0.0, -1.0, 0.01], rotation=[0, 0, 1, 0.0])
    bs.set_pose(3, scout, [0.21, -1.0, 0.06], rotation=[0, 0, 1, 0.0])     # back face at x = 0.06
    single = Simulation(arena(5), precision="exact")
    single.robot("epuck").set_pose([0.0, -1.0, 0.01], rotation=[0, 0, 1, 0.0])
    refs = [bs.device("epuck", f"ps{i}") for i in (0, 7)]
    for ref in refs:
        bs.enable(ref, 32)
        single.robot("epuck").device(ref.name).enable(32)
    bs.step()
    single.step()
    for ref in refs:
        seen, unseen = float(bs.value(ref)[3]), float(bs.value(ref)[4])
        assert seen > 200.0                    # the box 2.6 cm ahead: far above the no-hit level
        assert unseen == single.robot("epuck").device(ref.name).value   # exactly the world without it
        assert unseen < 130.0
    # drive straight ahead at full speed for 2 s (0.26 m): copy 3 stops at the scout's back face
    # (the kinematic contact's footprint of a box: its rectangle, 0.3 m long)
    bs.set_pose(3, scout, [0.35, -1.0, 0.06], rotation=[0, 0, 1, 0.0])
    bs.set_wheels(epuck, np.full(n, 6.28), np.full(n, 6.28))
    bs.run(62)
    assert bs.pos[3, epuck, 0] == pytest.approx(0.35 - 0.3 / 2 - 0.035, abs=1e-9)
    assert bs.pressing[3, epuck] or bs.counters["contacts"] > 0
    step_m = 6.28 * 0.0205 * 0.032
    for c in (0, 1, 2, 4, 5):
        assert bs.pos[c, epuck, 0] == pytest.approx(62 * step_m, abs=1e-9)     # through copy 3's scout


def test_reset_restarts_a_copy_without_rebuilding_anything():
    bs = BatchedSimulation(arena(1), 4, precision="fast")
    ref = bs.device("epuck", "ps0")
    bs.reset(np.arange(4), [1, 2, 3, 4])
    bs.enable(ref, 32)
    bs.set_wheels(bs.slot("epuck"), np.full(4, 3.0), np.full(4, 2.0))
    bs.run(10)
    first = bs.value(ref).copy()
    builds = bs.scene.engine.counters["bvh_builds"] + bs.rays.movers.counters["bvh_builds"]
    bs.reset(np.array([1, 2]), [2, 3])            # the same seeds again: those copies start over
    assert bs.time_ms.tolist() == [320, 0, 0, 320]
    assert math.isnan(bs.value(ref)[1]) and bs.pos[1, 0].tolist() == bs.initial[0].translation.tolist()
    bs.enable(ref, 32, copies=[1, 2])
    bs.set_wheels(bs.slot("epuck"), np.full(2, 3.0), np.full(2, 2.0), copies=[1, 2])
    active = np.array([False, True, True, False])
    bs.run(10, active)
    assert bs.time_ms.tolist() == [320, 320, 320, 320]
    assert bs.value(ref).tobytes() == first.tobytes()           # bit for bit the same ten steps
    assert bs.scene.engine.counters["bvh_builds"] + bs.rays.movers.counters["bvh_builds"] == builds


def test_what_the_batched_simulation_does_not_simulate_is_refused_with_a_reason():
    lw = load_world(default_world_path())
    w = lw.world
    odd = w.model_copy(update={"world_info": w.world_info.model_copy(update={"coordinate_system": "SWD"})})
    with pytest.raises(BatchedError, match="ENU or NUE worlds only"):      # (a model copied past validation)
        BatchedSimulation(odd, 2, base_dir=lw.base_dir)
    robots = [r.model_dump(mode="json", exclude_none=True) for r in w.robots]
    robots[0]["devices"].append({"device": "LED", "name": "led0"})
    lit = wm.World.model_validate({**w.model_dump(mode="json", exclude_none=True), "robots": robots})
    bs = BatchedSimulation(lit, 2, base_dir=lw.base_dir)
    with pytest.raises(BatchedError, match="is a LED"):
        bs.device("epuck", "led0")
    with pytest.raises(KeyError, match="no device 'nope'"):
        bs.device("epuck", "nope")


def test_a_writing_pen_whose_ink_a_sensor_would_read_is_refused():
    """The batched simulation lays no pen ink: a world where a writing pen's ink would be read (an
    infra-red sensor, a camera) is refused in one line; it used to run, its infra-red sensor reading
    the bare floor (10 here) where the single simulation reads the ink (50)."""
    down = [0.0, 1.0, 0.0, math.pi / 2]
    ir = {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "lookup_table": [[0, 0, 0], [1, 1000, 0]],
          "pose": {"translation": [0, 0, 0.01], "rotation": down}}

    def world(pen: dict, reader: dict) -> wm.World:
        return wm.World.model_validate({
            "world_info": {"contact": False}, "robots": [{"name": "r", "devices": [pen, reader]}],
            "solids": [{"name": "floor", "geometry": {"type": "plane", "size": [1, 1]}, "appearance": {}}]})

    pen = {"device": "Pen", "name": "pen", "pose": {"translation": [0, 0, 0.05]}, "ink_density": 1.0}
    sim = Simulation(world(pen, ir))
    sim.device("r/ir").enable(16)
    sim.step()
    assert sim.device("r/ir").value == pytest.approx(50.0)          # 0.01 m over black ink: 0.01 / 0.2
    with pytest.raises(BatchedError, match="pen 'pen' writes.*r/ir would not see it"):
        BatchedSimulation(world(pen, ir), 2)
    with pytest.raises(BatchedError, match="r/cam would not see it"):
        BatchedSimulation(world(pen, {"device": "Camera", "name": "cam"}), 2)
    # a pen that does not write, or a writing pen no sensor reads, is no difference
    BatchedSimulation(world({**pen, "write": False}, ir), 2)
    BatchedSimulation(world(pen, {**ir, "type": "generic"}), 2)


def test_wheel_encoders_with_noise_and_resolution_match_the_single_simulation():
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 0},
        "solids": [{"name": "floor", "geometry": {"type": "plane"}}],
        "robots": [{"name": "bot", "pose": {"translation": [0, 0, 0.05]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 6.0},
                    "devices": [{"device": "PositionSensor", "name": "left", "motor": "left wheel motor"},
                                {"device": "PositionSensor", "name": "right", "motor": "right wheel motor",
                                 "noise": 0.01, "resolution": 0.001}]}]})
    seeds = [3, 4]
    bs = BatchedSimulation(world, 2)
    bs.reset(np.arange(2), seeds)
    sims = [Simulation(world.model_copy(update={"world_info": world.world_info.model_copy(
        update={"random_seed": s})})) for s in seeds]
    for name, period in (("left", 16), ("right", 48)):
        bs.enable(bs.device("bot", name), period)
        for s in sims:
            s.robot("bot").device(name).enable(period)
    bs.set_wheels(0, np.array([2.0, -3.0]), np.array([1.5, 6.5]))       # 6.5 is clamped to 6
    for c, s in enumerate(sims):
        for m in s.robot("bot").motors.values():
            m.set_position(math.inf)
        s.robot("bot").drive.left.set_velocity([2.0, -3.0][c])
        s.robot("bot").drive.right.set_velocity([1.5, 6.5][c])
    for _ in range(30):
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for name in ("left", "right"):
                assert _same_value(s.robot("bot").device(name).value, float(bs.value(bs.device("bot", name))[c]))
            assert s.robot("bot").pose.translation.tobytes() == bs.pos[c, 0].tobytes()
    assert bs.value(bs.device("bot", "left"))[0] == pytest.approx(2.0 * 0.016 * 30, abs=1e-12)   # rad turned


def test_wheel_encoder_resolution_backwards_matches_the_single_simulation_and_webots():
    """Wheels turning backwards under an encoder with a resolution: Webots' discretize,
    (int)(v/res + 0.5)·res (toward zero for negatives), in both simulations, bit for bit."""
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16},
        "robots": [{"name": "bot", "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 6.0},
                    "devices": [{"device": "PositionSensor", "name": "enc", "motor": "left wheel motor",
                                 "resolution": 0.1}]}]})
    bs = BatchedSimulation(world, 1)
    bs.reset([0], [0])
    sim = Simulation(world)
    bs.enable(bs.device("bot", "enc"), 16)
    sim.device("bot/enc").enable(16)
    bs.set_wheels(0, np.array([-3.0]), np.array([-3.0]))
    for m in sim.robot("bot").motors.values():
        m.set_position(math.inf)
        m.set_velocity(-3.0)
    for k in range(1, 41):
        bs.step()
        sim.step()
        angle = sim.robot("bot").motor("left wheel motor").position
        assert angle == pytest.approx(-0.048 * k, abs=1e-12)
        want = math.trunc(angle / 0.1 + 0.5) * 0.1 + 0.0
        assert sim.device("bot/enc").value == want == float(bs.value(bs.device("bot", "enc"))[0]), k


def test_skid_steer_robots_match_the_single_simulation_with_every_wheel_of_a_side_driven():
    """Three wheels per side (the side's speed is the mean of its wheels, summed as the single
    simulation sums them) and an encoder on every wheel: poses and encoder values bit for bit."""
    left, right = ["l0", "l1", "l2"], ["r0", "r1", "r2"]
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 0},
        "robots": [{"name": "rover", "pose": {"translation": [0, 0, 0.1]},
                    "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.37, "max_wheel_speed": 7.0,
                                           "left_motor": "l0", "right_motor": "r0",
                                           "skid_steer": {"left": left[1:], "right": right[1:]}},
                    "devices": [{"device": "PositionSensor", "name": f"{m} sensor", "motor": m, "noise": 0.0}
                                for m in left + right]}]})
    bs = BatchedSimulation(world, 2)
    sims = [Simulation(world), Simulation(world)]
    for m in left + right:
        bs.enable(bs.device("rover", f"{m} sensor"), 16)
        for s in sims:
            s.robot("rover").device(f"{m} sensor").enable(16)
    rng = np.random.default_rng(2)
    for step in range(40):
        if step % 8 == 0:
            lr = rng.uniform(-7.0, 7.0, (2, 2))
            bs.set_wheels(0, lr[:, 0], lr[:, 1])
            for c, s in enumerate(sims):
                for names, v in ((left, lr[c, 0]), (right, lr[c, 1])):
                    for m in names:
                        s.robot("rover").motor(m).set_position(math.inf)
                        s.robot("rover").motor(m).set_velocity(float(v))
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            assert s.robot("rover").pose.translation.tobytes() == bs.pos[c, 0].tobytes(), (step, c)
            assert s.robot("rover").pose.rotation.tobytes() == bs.rot[c, 0].tobytes(), (step, c)
            for m in left + right:
                assert s.robot("rover").device(f"{m} sensor").value == float(bs.value(bs.device("rover", f"{m} sensor"))[c])
    assert bs.value(bs.device("rover", "l2 sensor")).tolist() == bs.value(bs.device("rover", "l0 sensor")).tolist()


def test_the_broad_phase_in_c_lists_the_numpy_pairs_and_meets_closed_form_cases():
    """copies.py's broad phase (each ray against the bounding spheres of its own copy's bodies):
    packets.copy_pairs (one C pass) lists exactly the pairs of the numpy path, in its order, for
    rays of several copies with per-ray and scalar excluded / mount slots and per-ray limits; and
    both pair a ray with a sphere exactly when its segment comes within the radius."""
    from sensorium.server.raycast import copies, packets

    if packets.library() is None:
        pytest.skip(packets.status())
    rng = np.random.default_rng(3)
    C, R, n = 5, 3, 4000
    centre = rng.uniform(-1.0, 1.0, (C, R, 3))
    r2 = np.array([0.25, -1.0, 0.36])                    # slot 1 has no body (never paired)
    present = r2 >= 0.0
    O = rng.uniform(-1.5, 1.5, (n, 3))
    D = rng.normal(size=(n, 3))
    D /= np.linalg.norm(D, axis=1)[:, None]
    copy = rng.integers(0, C, n)
    lim = rng.uniform(0.0, 3.0, n)
    lim[::7] = np.inf
    lim[::11] = -1.0                                      # nothing left to look at: never paired
    lim[::17] = np.nan
    no_hit = np.full(n, np.inf)
    for lo, excl, mount in ((0.0, -1, -1), (0.05, 2, -1), (0.0, rng.integers(-1, R, n), 0),
                            (rng.uniform(0.0, 0.1, n), -1, rng.integers(-1, R, n))):
        lo_b = np.broadcast_to(np.asarray(lo, dtype=np.float64), (n,))
        want = copies._pairs(O, D, copy, centre, r2, present, lo_b, lim, excl, mount)
        got = packets.copy_pairs(O, D, copy, centre, r2, present, lo, lim, excl, mount, no_hit)
        assert len(want[0]) > 50
        assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
    # the limits made in the pass from the rays' far limits and their static hits (np.minimum, NaN
    # on either side included): per-ray and scalar far limits
    dist = rng.uniform(0.0, 3.0, n)
    dist[::5] = np.inf
    dist[::13] = np.nan
    for far in (lim, 1.7, np.inf, np.nan):
        lim_m = np.minimum(far, dist)
        want = copies._pairs(O, D, copy, centre, r2, present, np.zeros(n), lim_m, -1, -1)
        got = packets.copy_pairs(O, D, copy, centre, r2, present, 0.0, far, -1, -1, dist)
        assert len(want[0]) > 50 or np.isnan(far).all()
        assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
    # closed form: a unit sphere at (2, 0, 0) of copy 1, rays along +x from the origin offset by h in y
    centre = np.zeros((2, 1, 3))
    centre[1, 0] = [2.0, 0.0, 0.0]
    h = np.array([0.0, 0.5, 0.999, 1.001, 2.0])
    O = np.stack([np.zeros(5), h, np.zeros(5)], axis=1)
    D = np.tile([1.0, 0.0, 0.0], (5, 1))
    for cp in (np.ones(5, dtype=np.int64), np.zeros(5, dtype=np.int64)):
        for lim_v, expect in ((10.0, [0, 1, 2]), (0.5, [])):    # the segment [0, 0.5] stays 1.5 m away
            lim = np.full(5, lim_v)
            got = packets.copy_pairs(O, D, cp, centre, np.array([1.0]), np.array([True]), 0.0, lim, -1, -1, no_hit[:5])
            want = copies._pairs(O, D, cp, centre, np.array([1.0]), np.array([True]), np.zeros(5), lim, -1, -1)
            rays = expect if cp[0] == 1 else [0, 1, 2]    # copy 0's sphere is at the origin: around the starts
            assert got[0].tolist() == want[0].tolist() == rays
            assert got[1].tolist() == [int(cp[0])] * len(rays)


def test_the_broad_phase_by_runs_lists_the_same_pairs():
    """packets.copy_pairs(run=k) (rays in runs of k sharing one origin and one copy: a copy's lidar
    scan, its clearance rays) lists the pairs of the ray-by-ray pass and of the numpy path, bit for
    bit: per-ray and scalar limits and near ends, NaN and infinite limits and static hits, NaN and
    signed-zero origins, excluded and mount slots, a shorter last run; and a run whose origin lies
    just within reach of a sphere (the segment's end on its surface) is not passed over, one just
    beyond it gives no pair (fails if the skip test or the per-run sums change)."""
    from sensorium.server.raycast import copies, packets

    if packets.library() is None:
        pytest.skip(packets.status())
    rng = np.random.default_rng(11)
    C, R = 6, 3
    centre = rng.uniform(-1.0, 1.0, (C, R, 3))
    r2 = np.array([0.04, -1.0, 0.09])
    present = r2 >= 0.0
    for run, runs in ((360, 23), (32, 70), (5, 301), (7, 1)):
        n = run * runs - (3 if runs > 1 else 0)            # the last run shorter
        rows = rng.uniform(-1.5, 1.5, (runs, 3))
        rows[1 % runs] = [-0.0, 0.0, -0.0]
        if runs > 2:
            rows[2] = [np.nan, 0.0, 0.0]
        O = np.repeat(rows, run, axis=0)[:n]
        copy = np.repeat(rng.integers(0, C, runs), run)[:n]
        D = rng.normal(size=(n, 3))
        D /= np.linalg.norm(D, axis=1)[:, None]
        D[::9] = [-0.0, 0.0, 1.0]
        dist = rng.uniform(0.0, 2.5, n)
        dist[::5] = np.inf
        dist[::13] = np.nan
        far_a = rng.uniform(0.0, 3.0, n)
        far_a[::7] = np.inf
        far_a[::17] = np.nan
        for lo, far, excl, mount in ((0.0, 0.6, -1, -1), (0.02, 6.0, 2, -1), (0.0, np.inf, -1, 0),
                                     (-0.3, 0.4, -1, -1), (0.0, np.nan, -1, -1), (0.05, far_a, -1, -1),
                                     (rng.uniform(0.0, 0.1, n), 1.0, rng.integers(-1, R, n), rng.integers(-1, R, n))):
            want = copies._pairs(O, D, copy, centre, r2, present, np.broadcast_to(np.asarray(lo, dtype=np.float64), (n,)),
                                 np.minimum(far, dist), excl, mount)
            plain = packets.copy_pairs(O, D, copy, centre, r2, present, lo, far, excl, mount, dist)
            got = packets.copy_pairs(O, D, copy, centre, r2, present, lo, far, excl, mount, dist, run)
            assert got[0].tobytes() == plain[0].tobytes() == want[0].tobytes()
            assert got[1].tobytes() == plain[1].tobytes() == want[1].tobytes()
    # a run of rays from the origin along +x with limit 1.5 against a sphere of radius 0.5 at
    # x = 2 (exactly within reach: the end of one segment on its surface) and at x = 2.01 (beyond)
    O = np.zeros((4, 3))
    D = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    for x, expect in ((2.0, [0]), (2.01, [])):
        centre = np.array([[[x, 0.0, 0.0]]])
        for run in (0, 4):
            got = packets.copy_pairs(O, D, np.zeros(4, dtype=np.int64), centre, np.array([0.25]), np.array([True]),
                                     0.0, 1.5, -1, -1, np.full(4, np.inf), run)
            assert got[0].tolist() == expect and got[1].tolist() == [0] * len(expect)


def test_the_contact_broad_phase_in_c_finds_the_numpy_candidates_and_meets_closed_form_cases():
    """BatchedSimulation._contact's broad phase: packets.contact_near (one C pass) flags exactly the
    solids, robots and near moves of the numpy path (_contact_near) for many copies' moves at
    random places (some robots without a footprint, some not moving); and a robot is a candidate
    of another exactly when their boxes grown by both reaches and radii overlap."""
    from sensorium.server.raycast import packets
    from sensorium.server.sim.contact import EPS, FLOOR

    if packets.library() is None:
        pytest.skip(packets.status())
    C = 40
    bs = BatchedSimulation(arena(2), C, precision="fast")
    ct = bs.contact
    assert ct is not None and len(ct._obs) > 0 and bs.R == 2
    rng = np.random.default_rng(7)
    seen_near: set[bool] = set()
    for trial in range(6):
        bs.centres[:, 0] = rng.uniform(-1.2, 1.2, (C, 2))
        bs.centres[:, 1] = bs.centres[:, 0] + rng.uniform(-0.3, 0.3, (C, 2))
        copies = np.repeat(np.arange(C), 2)
        slots = np.tile(np.arange(2), C)
        keep = rng.random(len(copies)) < 0.8
        copies, slots = copies[keep], slots[keep]
        starts = bs.centres[copies, slots].copy()
        step = rng.normal(scale=0.05 * (trial + 1), size=starts.shape)
        reach = np.hypot(*step.T) + EPS
        foot = bs.foot_radius.copy()
        if trial == 5:                                   # a robot without a footprint hits and is hit by nothing
            bs.foot_radius[1] = math.nan
        grow = np.zeros((C, 2))
        grow[copies, slots] = reach
        want = bs._contact_near(copies, slots, starts, reach, grow)
        got = packets.contact_near(copies, slots, starts, reach, bs.foot_radius, bs.foot_low, bs.foot_high,
                                   bs.heights, bs.centres, grow, ct._lo, ct._hi, ct._zlo, ct._zhi, EPS, FLOOR)
        bs.foot_radius[:] = foot
        assert got is not None and want[0] is not None and want[1] is not None
        for w, g in zip(want, got):
            assert g.dtype == np.bool_ and g.tobytes() == w.tobytes(), trial
        assert want[1].any() == (trial < 5)
        seen_near.update(want[2].tolist())
    assert seen_near == {False, True}
    # closed form: in copy 0 the two robots dx apart on y = 0, only robot 0 moving (reach q): a
    # candidate when dx <= q + r0 + r1 (its box grown by reach and its radius meets the other's disc)
    r0, r1 = float(bs.foot_radius[0]), float(bs.foot_radius[1])
    q = 0.01
    for dx, expect in ((q + r0 + r1 - 1e-6, True), (q + r0 + r1 + 1e-6, False)):
        bs.centres[0] = [[0.0, 0.0], [dx, 0.0]]
        bs.heights[0] = bs.heights[0, 0]
        grow = np.zeros((C, 2))
        grow[0, 0] = q
        args = (np.array([0]), np.array([0]), np.zeros((1, 2)), np.array([q]))
        got = packets.contact_near(*args, bs.foot_radius, bs.foot_low, bs.foot_high, bs.heights, bs.centres, grow,
                                   np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0), EPS, FLOOR)
        assert got is not None
        assert got[1].tolist() == [[False, expect]] and got[2].tolist() == [expect]


def test_the_wheels_in_c_turn_as_the_numpy_path_and_meet_closed_form_cases():
    """BatchedSimulation._drive's wheels and drives: packets.drive_wheels (one C pass) advances the
    wheel angles and gives the moving robots' copies, slots and speeds of the numpy path
    (_drive_wheels), bit for bit, for velocity and position control (targets reached, passed,
    NaN), still wheels, skid-steer sides and dt = 0; a wheel 0.1 rad from its target at 5 rad/s
    turns 0.1 / dt rad/s and stops on it."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(packets.status())
    C = 30
    bs = BatchedSimulation(arena(3), C, precision="fast")
    rng = np.random.default_rng(11)
    live = np.array(sorted(rng.choice(C, 24, replace=False)))
    driven = bs.has_drive.nonzero()[0]
    assert len(driven) == 2
    for trial, dt in enumerate((0.032, 0.032, 0.0, 0.016)):
        bs.velocity[:] = rng.uniform(-6.0, 6.0, (C, bs.R, 2)) * (rng.random((C, bs.R, 2)) < 0.8)
        bs.wheel_angle[:] = rng.uniform(-3.0, 3.0, (C, bs.R, 2))
        bs.target[:] = np.where(rng.random((C, bs.R, 2)) < 0.5, math.inf,
                                bs.wheel_angle + rng.uniform(-0.3, 0.3, (C, bs.R, 2)))
        bs.target[::5, :, 1] = bs.wheel_angle[::5, :, 1]              # on target: still
        bs.target[1, :, 0] = math.nan
        bs.velocity[::3], bs.target[::3] = 0.0, math.inf                  # still robots
        bs.side_wheels[:] = [[2, 3], [1, 1]] if trial % 2 else [[1, 1], [1, 1]]
        start = bs.wheel_angle.copy()
        want = bs._drive_wheels(live, driven, dt)
        want_angle, bs.wheel_angle[:] = bs.wheel_angle.copy(), start
        got = packets.drive_wheels(live, driven, bs.target, bs.velocity, bs.wheel_angle, dt, bs.side_wheels,
                                   bs.wheel_radius, bs.axle)
        assert got is not None
        assert bs.wheel_angle.tobytes() == want_angle.tobytes(), trial
        for w, g in zip(want, got):
            assert g.dtype == w.dtype and g.tobytes() == w.tobytes(), trial
        assert 0 < len(got[0]) < len(live) * len(driven) or dt == 0.0
    # closed form: the left wheel of copy 0's first driven slot 0.1 rad short of its target at 5 rad/s
    s = int(driven[0])
    bs.side_wheels[:] = 1
    bs.wheel_angle[0, s] = [1.0, 0.0]
    bs.target[0, s] = [1.1, math.inf]
    bs.velocity[0, s] = [5.0, 0.0]
    copies, slots, v, w = packets.drive_wheels(np.array([0]), np.array([s]), bs.target, bs.velocity, bs.wheel_angle,
                                               0.032, bs.side_wheels, bs.wheel_radius, bs.axle)
    omega = (1.1 - 1.0) / 0.032
    assert copies.tolist() == [0] and slots.tolist() == [s] and bs.wheel_angle[0, s, 0] == pytest.approx(1.1, abs=1e-15)
    r, axle = float(bs.wheel_radius[s]), float(bs.axle[s])
    assert v[0] == pytest.approx(r * omega / 2.0, rel=1e-12) and w[0] == pytest.approx(-r * omega / axle, rel=1e-12)


def test_the_lidar_beams_in_c_are_the_numpy_paths_and_meet_closed_form_cases():
    """BatchedSimulation._plan_lidars' beams: packets.lidar_beams (one C pass) gives the origins,
    directions and float32 directions of the numpy path (batched._lidar_beams), bit for bit, for
    many scans of many beams, one beam, no scan; a scan turned 90 degrees about z sends the beam
    (1, 0, 0) along (0, 1, 0) from its origin."""
    from sensorium.server.raycast import packets
    from sensorium.server.sim import batched

    if packets.library() is None:
        pytest.skip(packets.status())
    rng = np.random.default_rng(5)
    for n, W in ((64, 360), (3, 1), (0, 4)):
        rot = rng.normal(size=(n, 3, 3))
        org = rng.normal(size=(n, 3))
        cols = tuple(rng.normal(size=W) for _ in range(3))
        want = batched._lidar_beams(rot, org, cols)
        got = packets.lidar_beams(rot, org, cols)
        assert got is not None
        for w, g in zip(want, got):
            assert g.dtype == w.dtype and g.shape == w.shape == (n * W, 3) and g.tobytes() == w.tobytes()
        buffers = tuple(np.full_like(w, np.nan) for w in want)        # written over, as scan after scan
        again = packets.lidar_beams(rot, org, cols, buffers)
        assert again is not None and all(a is b and a.tobytes() == w.tobytes() for a, b, w in zip(again, buffers, want))
    with pytest.raises(TypeError, match="lidar_beams: writes contiguous float32"):
        packets.lidar_beams(rot, org, cols, (buffers[0], buffers[1], buffers[1]))
    rz = np.array([[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]])
    got = packets.lidar_beams(rz, np.array([[1.0, 2.0, 3.0]]),
                              (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([0.0, 0.0])))
    assert got is not None
    o, d, d32 = got
    assert o.tolist() == [[1.0, 2.0, 3.0]] * 2 and d.tolist() == [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
    assert d32.tolist() == d.tolist()


def test_every_copys_lidar_gets_its_single_world_scan_at_many_poses():
    """The copies' lidar beams go out in one cast traced as the single world traces one lidar
    (coherent packets in FAST: a beam within float32 rounding of an edge gets the same triangle):
    at 24 scattered poses with the beams level with the crate's top face (z = 0.2: every beam
    that meets the crate grazes it), each copy's range image equals a Simulation's with the scout
    there, bit for bit."""
    n = 24
    rng = np.random.default_rng(4)
    bs = BatchedSimulation(arena(2), n, precision="fast")
    bs.reset(np.arange(n), [2] * n)
    scout = bs.slot("scout")
    ref = bs.device("scout", "lidar")
    bs.enable(ref, 32)
    poses = [([float(rng.uniform(0.0, 1.8)), float(rng.uniform(-1.5, 0.3)), 0.2 - 0.09], float(rng.uniform(-3.1, 3.1)))
             for _ in range(n)]
    for c, (xyz, yaw) in enumerate(poses):
        bs.set_pose(c, scout, xyz, rotation=[0, 0, 1, yaw])
    bs.step()
    single = Simulation(arena(2), precision="fast")
    lidar = single.robot("scout").device("lidar")
    lidar.enable(32)
    seen = 0
    for c, (xyz, yaw) in enumerate(poses):
        single.robot("scout").set_pose(xyz, rotation=[0, 0, 1, yaw])
        single.step()
        img = lidar.range_image
        assert img.tobytes() == bs.range_image(ref)[c].tobytes(), (c, np.flatnonzero(img != bs.range_image(ref)[c])[:5])
        seen += np.count_nonzero(np.isfinite(img))
    assert seen > n * 100


def test_noise_streams_give_each_streams_numbers_in_order_whatever_the_block():
    """A (copy, device) stream's draws through NoiseStreams (next over many streams, take) are
    device_rng(seed, path)'s standard normals in order, across refills, for any block size."""
    from sensorium.server.devices.noise import device_rng
    from sensorium.server.sim.batched import NoiseStreams

    paths = ["r/a", "r/b", "q/c"]
    want = {(c, d): device_rng(100 + c, paths[d]).standard_normal(700) for c in range(4) for d in range(3)}
    for block in (64, 100, 256):
        ns = NoiseStreams(4, paths, block=block)
        ns.reseed(range(4), [100 + c for c in range(4)])
        got: dict = {key: [] for key in want}
        copies, devs = np.array([0, 1, 3, 2, 0]), np.array([0, 2, 1, 1, 1])
        for _ in range(300):        # several refills of the streams drawn together
            for k, v in zip(zip(copies.tolist(), devs.tolist()), ns.next(copies, devs).tolist()):
                got[k].append(v)
        for k in got:
            got[k] += ns.take(k[0], k[1], 700 - len(got[k])).tolist()
        for k, v in want.items():
            assert np.array(got[k]).tobytes() == v.tobytes(), (block, k)


@pytest.mark.skipif(packets.library() is None, reason="no compiled helper here")
def test_distance_sensor_rays_in_c_are_the_numpy_frames_bit_for_bit():
    """packets.sensor_rays (the batched distance sensors' world rays in one C pass) gives the numpy
    path's positions, origins and directions (batches._frames_t, _rotate_t) bit for bit, signed zeros
    included: random and axis-aligned robot and sensor frames, sensors gathered in any order."""
    from sensorium.server.sim.batches import _frames_t, _rotate_t

    rng = np.random.default_rng(11)

    def frames(m):
        q = np.linalg.qr(rng.normal(size=(m, 3, 3)))[0]
        aligned = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], 3)[:, None]
        q[rng.uniform(size=m) < 0.5] = aligned          # exact zeros: the signed zeros of the sums
        return q

    C, R, P, G, N, S = 7, 3, 9, 5, 4, 40
    rot, pos = frames(C * R).reshape(C, R, 3, 3), rng.normal(size=(C, R, 3)) * 10.0
    local_rot, local_pos = frames(P), rng.normal(size=(P, 3)) * 0.1
    local_dirs = rng.normal(size=(G, N, 3))
    local_dirs[:, 0] = [1.0, 0.0, 0.0]
    c, slot = rng.integers(0, C, S), rng.integers(0, R, S)
    pi, k = rng.integers(0, P, S), rng.integers(0, G, S)
    positions, origins, dirs = packets.sensor_rays(c, slot, rot, pos, pi, local_rot, local_pos, k, local_dirs)
    rot_t, pos_t = _frames_t(np.ascontiguousarray(rot[c, slot].transpose(1, 2, 0)),
                             np.ascontiguousarray(local_rot.transpose(1, 2, 0)[:, :, pi]),
                             np.ascontiguousarray(local_pos.T[:, pi]))
    want_pos = pos_t.T + pos[c, slot]
    want_dirs = _rotate_t(rot_t, np.ascontiguousarray(local_dirs.transpose(2, 1, 0)[:, :, k]))
    assert positions.tobytes() == want_pos.tobytes()
    assert origins.tobytes() == np.repeat(want_pos, N, axis=0).tobytes()
    assert dirs.tobytes() == want_dirs.tobytes()
    assert np.count_nonzero(want_dirs == 0.0) > 0            # exact zeros were summed (their signs compared)
    # the kept pass (packets.SensorRays: the same sensors step after step) reads the poses written
    # in place since it was made, and gives sensor_rays' answer for them
    kept = packets.sensor_rays_of(c, slot, rot, pos, pi, local_rot, local_pos, k, local_dirs)
    rot[:], pos[:] = frames(C * R).reshape(C, R, 3, 3), rng.normal(size=(C, R, 3))
    for got, want in zip(kept(), packets.sensor_rays(c, slot, rot, pos, pi, local_rot, local_pos, k, local_dirs)):
        assert got.tobytes() == want.tobytes()


@pytest.mark.parametrize("turning", ["all", "none", "mixed"])
def test_arc_steps_are_motion_arc_step_bit_for_bit(turning):
    """The batched drive's arcs (every robot turning, none, some) are motion.arc_step's, robot by robot."""
    from sensorium.server.sim.batched import _arc_steps
    from sensorium.server.sim.motion import arc_step

    rng = np.random.default_rng({"all": 1, "none": 2, "mixed": 3}[turning])
    n, dt = 50, 0.032
    x, y, yaw, v = rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), rng.uniform(-math.pi, math.pi, n), rng.normal(size=n)
    w = rng.normal(size=n) * 3.0
    if turning != "all":
        w[: n if turning == "none" else n // 2] = rng.choice([0.0, 1e-12, -2e-8], n if turning == "none" else n // 2)
    got = _arc_steps(x, y, yaw, v, w, dt)
    want = np.array([arc_step(*a, dt) for a in zip(x.tolist(), y.tolist(), yaw.tolist(), v.tolist(), w.tolist())]).T
    for g, wa in zip(got, want):
        assert np.asarray(g).tobytes() == wa.tobytes()


def test_arc_steps_in_c_are_the_numpy_arcs_and_poses_bit_for_bit(monkeypatch):
    """packets.arc_steps (the batched drive: every moving robot's arc and its new yaw's cos and sin
    in one C pass) gives _arc_steps' x, y, yaw (numpy's products, libm's cos/sin through math.cos
    and math.sin, numpy's remainder) and math.cos/math.sin of the new yaw, bit for bit: robots all
    turning, all straight (|w dt| < 1e-9) and mixed; yaws at +-pi and multiples of 2 pi (remainder
    0), signed zeros, huge angles, NaN speeds; an infinite angle is left to the Python way."""
    from sensorium.server.sim.batched import _arc_steps
    from sensorium.server.sim.batched_kinematic import libm_cos_sin as _cos_sin

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(12)
    n = 5000
    x, y = rng.uniform(-3.0, 3.0, n), rng.uniform(-3.0, 3.0, n)
    yaw = np.concatenate([rng.uniform(-math.pi, math.pi, n - 500), rng.uniform(-1e4, 1e4, 490),
                          [math.pi, -math.pi, 0.0, -0.0, 3 * math.pi, -3 * math.pi, 1e-300, math.pi / 2, 1e15, -1e15]])
    v = rng.uniform(-1.0, 1.0, n)
    v[::17] = 0.0
    v[::29] = -0.0
    w = rng.uniform(-20.0, 20.0, n)
    w[::5] = rng.uniform(-1e-7, 1e-7, len(w[::5]))          # straight: |w dt| < 1e-9 for most
    w[::11] = 0.0
    w[::13] = -0.0
    w[7] = np.nan
    v[9] = np.nan
    monkeypatch.setattr(packets, "cos_sin", lambda a: None)  # the reference: math.cos / math.sin
    dt = 0.016
    turning = np.abs(w * dt) >= 1e-9
    for rows in (np.arange(n), turning.nonzero()[0], (~turning).nonzero()[0], np.arange(0, n, 3)):
        args = (x[rows], y[rows], yaw[rows], v[rows], w[rows])
        want = _arc_steps(*args, dt)
        want = (*want, *_cos_sin(want[2]))
        got = packets.arc_steps(*args, dt)
        assert got is not None and len(rows) > 100
        for g, r in zip(got, want):
            assert g.tobytes() == r.tobytes()
    # remainder 0: the new yaw is -pi (numpy's +0.0 remainder), whose cos is -1
    got = packets.arc_steps(np.zeros(1), np.zeros(1), np.array([math.pi]), np.zeros(1), np.zeros(1), dt)
    assert got is not None and got[2][0] == -math.pi and got[3][0] == -1.0
    assert packets.arc_steps(np.zeros(2), np.zeros(2), np.array([0.0, math.inf]), np.ones(2), np.ones(2), dt) is None


def test_cos_sin_in_c_are_math_cos_and_sin_bit_for_bit():
    """packets.cos_sin (the batched drive's poses and arcs) gives what math.cos and math.sin give,
    element by element, on random angles of every magnitude, signed zeros, NaN, multiples of pi and
    subnormals; an infinite angle is left to the Python way (math.cos refuses it)."""
    from sensorium.server.sim.batched_kinematic import libm_cos_sin as _cos_sin

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(7)
    a = np.concatenate([rng.uniform(-7.0, 7.0, 20000), rng.uniform(-1e6, 1e6, 2000),
                        10.0 ** rng.uniform(-320, 300, 2000) * rng.choice([-1.0, 1.0], 2000),
                        [0.0, -0.0, math.nan, math.pi, -math.pi, math.pi / 2, 3 * math.pi / 4, 1e-300, 5e-324, 1e22]])
    got = packets.cos_sin(a)
    assert got is not None
    want = [np.array([f(x) for x in a.tolist()]) for f in (math.cos, math.sin)]
    for g, w in zip(got, want):
        assert g.tobytes() == w.tobytes()
    assert _cos_sin(a[:50])[1].tobytes() == want[1][:50].tobytes()
    assert packets.cos_sin(np.array([0.5]))[0][0] == math.cos(0.5)
    assert packets.cos_sin(np.array([0.5, math.inf])) is None
    with pytest.raises(ValueError):
        _cos_sin(np.array([0.5, -math.inf]))


def test_a_kind_never_enabled_is_never_due_and_enabling_it_later_measures_on_its_period():
    """Devices of a kind no copy ever enabled are not looked at (nothing is due: no measurement,
    values stay NaN); enabling one later in some copies measures it there on its period from
    that moment, as a single simulation does, and disabling it again (period 0) stops it."""
    bs = BatchedSimulation(arena(3), 4, precision="fast")
    ref = bs.device("epuck", "ls0")
    bs.run(3)
    assert bs.counters["measurements"] == 0 and np.isnan(bs.value(ref)).all()
    dt = bs.basic_time_step
    period = 4 * dt
    bs.enable(ref, period, copies=[1, 2])              # due 4 basic steps from now
    bs.run(3)
    assert bs.counters["measurements"] == 0
    bs.run(1)
    assert bs.counters["measurements"] == 2
    values = bs.value(ref)
    assert np.isnan(values[[0, 3]]).all() and np.isfinite(values[[1, 2]]).all()
    single = Simulation(arena(3), precision="fast")
    single.run(3)
    single.robot("epuck").device("ls0").enable(period)
    single.run(4)
    assert single.robot("epuck").device("ls0").value == float(values[1])
    bs.enable(ref, 0, copies=[1, 2])
    bs.run(8)
    assert bs.counters["measurements"] == 2


def _hills(seed: int) -> wm.World:
    """Two robots with bodies (contact between them and a wall) on a floor with a rough terrain and a
    ramp on it: they climb, cross ridges, drive off onto the floor."""
    rng = np.random.default_rng(99)
    nx = ny = 9
    rough = rng.uniform(0.0, 0.3, nx * ny)
    rough[[0, nx - 1, -nx, -1]] = 0.0
    ramp = [0.2 * i * 0.5 for j in range(5) for i in range(5)]
    body = {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.08}}
    devices = [{"device": "DistanceSensor", "name": "front", "pose": {"translation": [0.1, 0.0, 0.02]},
                "lookup_table": [[0, 0, 0], [2, 2, 0]]},
               {"device": "DistanceSensor", "name": "down", "pose": {"translation": [0.05, 0.0, 0.0],
                                                                     "rotation": [0, 1, 0, 1.2]},
                "lookup_table": [[0, 0, 0], [2, 2, 0.01]]},
               {"device": "Lidar", "name": "lidar", "horizontal_resolution": 64, "number_of_layers": 3,
                "field_of_view": 3.0, "vertical_field_of_view": 0.3, "max_range": 4.0},
               {"device": "PositionSensor", "name": "enc", "motor": "left wheel motor"}]
    drive = {"wheel_radius": 0.05, "axle_length": 0.25, "max_wheel_speed": 12.0}
    return wm.World.model_validate({
        "world_info": {"random_seed": seed},
        "solids": [{"name": "floor", "geometry": {"type": "plane"}},
                   {"name": "rough", "pose": {"translation": [-2.0, -2.0, 0.0], "rotation": [0, 0, 1, 0.3]},
                    "geometry": {"type": "elevation_grid", "height": rough.tolist(), "x_dimension": nx,
                                 "x_spacing": 0.5, "y_dimension": ny, "y_spacing": 0.5}},
                   {"name": "ramp", "pose": {"translation": [1.5, -1.0, 0.0]},
                    "geometry": {"type": "elevation_grid", "height": ramp, "x_dimension": 5, "x_spacing": 0.5,
                                 "y_dimension": 5, "y_spacing": 0.5}},
                   {"name": "wall", "pose": {"translation": [3.2, 0.0, 0.5]}, "geometry": {"type": "box", "size": [0.1, 6, 1]}}],
        "robots": [{"name": "a", "pose": {"translation": [-0.3, -0.2, 0.3], "rotation": [0, 0, 1, 0.4]},
                    "body": body, "differential_drive": drive, "devices": devices},
                   {"name": "b", "pose": {"translation": [1.2, 0.3, 0.06], "rotation": [0, 0, 1, -0.2]},
                    "body": body, "differential_drive": drive, "devices": devices}]})


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_copies_riding_terrains_are_the_single_simulation_bit_for_bit(precision):
    """Robots riding a rough terrain and a ramp (heights, attitudes, contact bands), random wheel
    commands, a supervisor move onto a slope: every copy's poses, distance readings, range images
    and encoders equal a Simulation's with that copy's seed after every step, bit for bit."""
    seeds = [3, 4, 5]
    bs = BatchedSimulation(_hills(0), len(seeds), precision=precision)
    bs.reset(np.arange(3), seeds)
    sims = [Simulation(_hills(s), precision=precision) for s in seeds]
    names = ["front", "down", "lidar", "enc"]
    for robot in ("a", "b"):
        for n in names:
            bs.enable(bs.device(robot, n), 32)
            for s in sims:
                s.robot(robot).device(n).enable(32)
    rng = np.random.default_rng(1)
    tilted = 0
    for step in range(120):
        if step % 12 == 0:
            for robot in ("a", "b"):
                slot = bs.slot(robot)
                lr = rng.uniform(-12.0, 12.0, (3, 2)) if step % 24 else np.full((3, 2), 10.0)
                bs.set_wheels(slot, lr[:, 0], lr[:, 1])
                for c, s in enumerate(sims):
                    _drive_single(s, robot, float(lr[c, 0]), float(lr[c, 1]))
        if step == 60:                        # a supervisor puts copy 1's robot a onto the ramp's slope
            bs.set_pose(1, bs.slot("a"), [2.3, -0.5, 0.5])
            sims[1].robot("a").set_pose([2.3, -0.5, 0.5])
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot in ("a", "b"):
                slot = bs.slot(robot)
                pose = s.robot(robot).pose
                assert pose.rotation.tobytes() == bs.rot[c, slot].tobytes(), (step, c, robot)
                assert pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c, robot)
                tilted += abs(pose.rotation[2, 2]) < 1.0 - 1e-6
                for n in names:
                    ref, dev = bs.device(robot, n), s.robot(robot).device(n)
                    if ref.kind == "Lidar":
                        assert dev.range_image.tobytes() == bs.range_image(ref)[c].tobytes(), (step, c, n)
                    else:
                        assert _same_value(dev.value, float(bs.value(ref)[c])), (step, c, robot, n)
    assert tilted > 100                       # they did ride slopes
    assert bs.ground is not None and len({float(z) for z in bs.pos[:, :, 2].ravel()}) > 3


def _drive_single(sim: Simulation, robot: str, left: float, right: float) -> None:
    for m in sim.robot(robot).motors.values():
        m.set_position(math.inf)
    sim.robot(robot).drive.left.set_velocity(left)
    sim.robot(robot).drive.right.set_velocity(right)


def _crowd(seed: int) -> wm.World:
    """Three robots with bodies close together (a skid-steer one among them) between walls, a
    sphere and a ramp: they run into the walls, the sphere and one another."""
    ramp = [0.15 * i * 0.5 for j in range(4) for i in range(4)]
    drive = {"wheel_radius": 0.05, "axle_length": 0.25, "max_wheel_speed": 14.0}
    skid = {**drive, "left_motor": "l0", "right_motor": "r0", "skid_steer": {"left": ["l1"], "right": ["r1"]}}
    return wm.World.model_validate({
        "world_info": {"random_seed": seed, "basic_time_step": 16},
        "solids": [{"name": "floor", "geometry": {"type": "plane"}},
                   {"name": "ramp", "pose": {"translation": [-0.3, 0.2, 0.0]},
                    "geometry": {"type": "elevation_grid", "height": ramp, "x_dimension": 4, "x_spacing": 0.3,
                                 "y_dimension": 4, "y_spacing": 0.3}},
                   {"name": "east", "pose": {"translation": [0.9, 0.0, 0.25]},
                    "geometry": {"type": "box", "size": [0.1, 3, 0.5]}},
                   {"name": "west", "pose": {"translation": [-0.9, 0.0, 0.25], "rotation": [0, 0, 1, 0.3]},
                    "geometry": {"type": "box", "size": [0.1, 3, 0.5]}},
                   {"name": "ball", "pose": {"translation": [0.0, -0.45, 0.1]},
                    "geometry": {"type": "sphere", "radius": 0.12}}],
        "robots": [{"name": "a", "pose": {"translation": [-0.2, 0.0, 0.05]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.08, "height": 0.08}},
                    "differential_drive": drive},
                   {"name": "b", "pose": {"translation": [0.2, 0.0, 0.05], "rotation": [0, 0, 1, math.pi]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.08, "height": 0.08}},
                    "differential_drive": drive},
                   {"name": "c", "pose": {"translation": [0.0, 0.35, 0.06], "rotation": [0, 0, 1, -1.5]},
                    "body": {"geometry": {"type": "box", "size": [0.2, 0.12, 0.1]}},
                    "differential_drive": skid}]})


def test_the_drive_in_c_moves_every_copy_as_the_numpy_drive_with_contacts_and_terrain():
    """The batched drive's C pass (wheels, arcs, the contact broad phase, the poses: one pass,
    then the narrow phase where a move is near something) against its numpy path, over 12 copies
    of three robots crowded between walls, a sphere and a ramp (one skid-steer), random wheel
    commands and random copies sitting steps out: after every step every state array is the
    same, bit for bit; robots clip on walls and on one another (two discs end touching: their
    centres the sum of their radii apart)."""
    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    n = 12
    fast, ref = BatchedSimulation(_crowd(1), n), BatchedSimulation(_crowd(1), n)
    ref._drive_step = None                       # the numpy path
    rng = np.random.default_rng(5)
    for bs in (fast, ref):
        bs.reset(np.arange(n), list(range(n)))
    starts = rng.uniform(-0.05, 0.05, (n, 3, 2))
    for bs in (fast, ref):
        for c in range(n):
            for r in range(3):
                p = bs.pos[c, r]
                bs.set_pose(c, r, [p[0] + starts[c, r, 0], p[1] + starts[c, r, 1], p[2]])
    closest, tilted = math.inf, 0
    for step in range(150):
        if step % 10 == 0:
            lr = rng.uniform(-14.0, 14.0, (3, n, 2))
            lr[:2, :, :] = np.abs(lr[:2, :, :]) * (step % 30 == 0) + lr[:2] * (step % 30 != 0)   # a and b: at each other
            for bs in (fast, ref):
                for r in range(3):
                    bs.set_wheels(r, lr[r, :, 0], lr[r, :, 1])
        active = rng.uniform(size=n) > 0.2
        fast.step(active)
        ref.step(active)
        for name in ("x", "y", "z", "yaw", "rot", "pos", "centres", "heights", "pressing", "wheel_angle", "tilted"):
            assert getattr(fast, name).tobytes() == getattr(ref, name).tobytes(), (step, name)
        assert fast.counters == ref.counters
        gap = np.hypot(*(fast.centres[:, 0] - fast.centres[:, 1]).T).min()
        closest = min(closest, float(gap))
        tilted += int(np.count_nonzero(fast.tilted))
    assert fast.counters["contacts"] > 20
    assert closest == pytest.approx(0.16, abs=1e-6)             # a and b touched (radii 0.08 each)
    assert tilted > 50                                           # robots rode the ramp


def test_distance_sensors_of_every_kind_and_table_match_the_single_simulation_as_due_sets_change():
    """Distance sensors of every type on one robot, sharing and not sharing tables (two noisy, one
    empty: value 0), with and without resolution, on periods of 16, 32
    and 48 ms so that the due set changes from step to step (the kept rows, plans and outputs are
    remade each time): every copy's values equal a Simulation's with that copy's seed, bit for bit."""
    near = [[0.0, 0.0, 0.0], [1.0, 100.0, 0.0], [2.0, 150.0, 0.0]]
    devices = [
        {"device": "DistanceSensor", "name": "generic", "lookup_table": near, "resolution": 0.5,
         "number_of_rays": 4, "aperture": 0.3},
        {"device": "DistanceSensor", "name": "ir", "type": "infra-red", "lookup_table": [[0, 1000, 0.02], [0.5, 0, 0.05]],
         "number_of_rays": 3, "aperture": 0.2, "pose": {"rotation": [0, 0, 1, 0.7]}},
        {"device": "DistanceSensor", "name": "sonar", "type": "sonar", "lookup_table": near, "number_of_rays": 5,
         "aperture": 0.5, "pose": {"rotation": [0, 0, 1, -0.5]}},
        {"device": "DistanceSensor", "name": "laser", "type": "laser", "lookup_table": [[0, 0, 0], [3, 30, 0]],
         "resolution": 0.1, "pose": {"rotation": [0, 0, 1, 3.0]}},
        {"device": "DistanceSensor", "name": "far", "lookup_table": [[0.2, 80, 0.01], [1.5, 10, 0.0], [3.0, 5, 0.02]],
         "pose": {"rotation": [0, 0, 1, 1.6]}},
        {"device": "DistanceSensor", "name": "blank", "lookup_table": []},
    ]
    periods = {"generic": 16, "ir": 32, "sonar": 48, "laser": 16, "far": 32, "blank": 48}
    world = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 0},
        "solids": [{"name": "floor", "geometry": {"type": "plane"}},
                   {"name": "box", "pose": {"translation": [0.6, 0.1, 0.1]}, "geometry": {"type": "box", "size": [0.2, 0.6, 0.2]}},
                   {"name": "post", "pose": {"translation": [-0.5, 0.4, 0.2]},
                    "geometry": {"type": "cylinder", "radius": 0.1, "height": 0.4}}],
        "robots": [{"name": "r", "pose": {"translation": [0, 0, 0.05]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.05, "height": 0.05}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.1, "max_wheel_speed": 10.0},
                    "devices": devices}]})
    seeds = [21, 22, 23]
    bs = BatchedSimulation(world, len(seeds))
    bs.reset(np.arange(3), seeds)
    sims = [Simulation(world.model_copy(update={"world_info": world.world_info.model_copy(update={"random_seed": s})}))
            for s in seeds]
    for name, period in periods.items():
        bs.enable(bs.device("r", name), period)
        for s in sims:
            s.robot("r").device(name).enable(period)
    rng = np.random.default_rng(6)
    for step in range(60):
        if step % 10 == 0:
            lr = rng.uniform(-10.0, 10.0, (3, 2))
            bs.set_wheels(0, lr[:, 0], lr[:, 1])
            for c, s in enumerate(sims):
                _drive_single(s, "r", float(lr[c, 0]), float(lr[c, 1]))
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for name in periods:
                want = s.robot("r").device(name).value
                assert _same_value(want, float(bs.value(bs.device("r", name))[c])), (step, c, name, want)
    assert bs.value(bs.device("r", "blank")).tolist() == [0.0, 0.0, 0.0]
    assert len(set(bs.value(bs.device("r", "ir")).tolist())) == 3        # each copy's own noise


def test_the_due_scan_in_c_lists_the_pairs_numpy_lists():
    """packets.DueScan (BatchedSimulation._due over every copy in one C pass) against _due's numpy
    steps on clocks, last times and periods drawn at random (disabled devices, periods just
    elapsed, just not, far past), also after the arrays are written in place between scans (it
    reads them, not copies); and a batched simulation's _due with and without it."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(11)
    C, D = 37, 5
    time = rng.integers(0, 400, C).astype(np.int64)
    last = np.zeros((C, D), dtype=np.int64)
    per = np.zeros((C, D), dtype=np.int64)
    scan = packets.due_scan(time, last, per)
    assert scan is not None
    for _ in range(20):
        per[...] = rng.choice([0, 8, 16, 32, 64], (C, D))
        last[...] = time[:, None] - rng.integers(0, 80, (C, D))
        time += rng.integers(0, 3, C)
        want = ((per > 0) & (time[:, None] - last >= per)).nonzero()
        got = scan()
        assert got[0].dtype == np.int64 and got[1].dtype == np.int64
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
        assert 0 < len(got[0]) < C * D
    bs = BatchedSimulation(arena(3), 4, precision="fast")
    bs.reset(np.arange(4), [3] * 4)
    ref = bs.device("epuck", "ps0")
    bs.enable(ref, 64, np.array([1, 3]))
    bs.enable(ref, 32, np.array([0]))
    every = np.arange(4)
    seen = set()
    for _ in range(6):
        bs.time_ms += 16          # (the clocks moved on, in place, as step moves them)
        got = bs._due("DistanceSensor", every)
        saved, bs._due_scans = bs._due_scans, {"DistanceSensor": None}
        want = bs._due("DistanceSensor", every)
        bs._due_scans = saved
        assert all(np.array_equal(g, w) for g, w in zip(got, want))
        seen.add(tuple(got[0].tolist()))
    assert bs._due_scans["DistanceSensor"] is not None and {(0,), (0, 1, 3)} <= seen
