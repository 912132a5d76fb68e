"""GPS, Compass, InertialUnit, Gyro and Accelerometer in the batched simulation
(sensorium/server/sim/batched_kinematic.py): every copy bit-identical to the single Simulation with its
seed (with the C helper and without it), closed-form readings, the C passes against the ``math`` path,
the vector environment observing them, and what stays refused."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from _packets import use_packets

from sensorium.schemas import world as wm
from sensorium.server.devices import motion_sensors as motion_math
from sensorium.server.devices import orientation as orient
from sensorium.server.raycast import packets
from sensorium.server.sim import batched_kinematic as kin
from sensorium.server.sim.batched import BatchedError, BatchedSimulation, check_observable
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from sensorium.server.world.poses import matrix_quaternion, quaternion_matrix
from tests.test_batched_sim import _enable_both, _wheels_both
from tests.test_gym_vector import _reset_both, _step_both

WORLD = Path(__file__).parent / "worlds" / "kinematic.yaml"
PERIODS = {"rover": {"gps": 48, "plain_gps": 16, "compass": 32, "plain_compass": 16, "imu": 48, "flat_imu": 16,
                     "plain_imu": 16, "gyro": 16, "plain_gyro": 32, "acc": 16, "plain_acc": 48},
           "scout": {"gps": 32, "compass": 16, "imu": 16, "gyro": 16, "acc": 32}}


def _world(seed: int) -> LoadedWorld:
    lw = load_world(WORLD)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _readings(bs: BatchedSimulation, sim: Simulation, copy: int, robot: str, name: str):
    """(what, single simulation's value, batched value) of every reading of a device."""
    ref, dev = bs.device(robot, name), sim.robot(robot).device(name)
    whats = kin.READINGS[ref.kind]
    return [(w, np.asarray(getattr(dev, w), dtype=np.float64), bs.reading(ref, w)[copy]) for w in whats]


@pytest.fixture(params=["helper", "math"])
def native(request, monkeypatch):
    """The batched kinematic passes in C (the packets helper) or, with ``SENSORIUM_PACKETS=0``, their
    ``math`` fallback."""
    use_packets(request.param == "helper", monkeypatch)
    return request.param


def test_every_copy_reads_its_kinematic_devices_as_the_single_simulation(native):
    """Two robots driving on a floor and a ramp with random, per-copy wheel commands; GPS with
    Gauss-Markov noise, speed noise and resolutions, compasses with noisy lookup tables and a
    disabled axis, inertial units with noise, resolution, disabled axes and tilted mounts, gyros
    and accelerometers with noisy tables, resolutions, disabled axes, tilted and offset mounts, at
    different periods; a supervisor move, a re-enable and a reset with a new seed on the way: after
    every basic step every reading of every copy equals that of a Simulation built with that copy's
    seed, bit for bit (NaNs and signed zeros included), with the C helper and without it."""
    seeds = [5, 6, 7, 8]
    bs = BatchedSimulation(_world(0), len(seeds))
    bs.reset(np.arange(len(seeds)), seeds)
    sims = [Simulation(_world(s)) for s in seeds]

    for c in range(len(seeds)):
        _enable_both(bs, sims, PERIODS, c)
    rng = np.random.default_rng(0)
    seen = {"tilted": 0, "nan": 0, "speed": 0, "turn": 0, "jolt": 0}
    for step in range(160):
        if step % 10 == 0:
            for robot in PERIODS:
                vmax = float(bs.max_wheel[bs.slot(robot), 0])
                _wheels_both(bs, sims, robot, rng.uniform(-vmax, vmax, (len(seeds), 2)))
        if step == 70:                          # a supervisor move onto the ramp in copy 2
            bs.set_pose(2, bs.slot("rover"), [0.9, -0.3, 0.5])
            sims[2].robot("rover").set_pose([0.9, -0.3, 0.5])
        if step == 100:                         # copy 1 as a new world with another seed
            bs.reset([1], [42])
            sims[1] = Simulation(_world(42))
            _enable_both(bs, sims, PERIODS, 1)
        if step == 120:                         # copy 3's gyro and accelerometer start their poses over
            for n, p in (("acc", 32), ("gyro", 48)):
                bs.enable(bs.device("scout", n), p, copies=[3])
                sims[3].robot("scout").device(n).enable(p)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            assert s.time_ms == bs.time_ms[c]
            seen["tilted"] += abs(s.robot("rover").pose.rotation[2, 2]) < 1.0 - 1e-6
            for robot, names in PERIODS.items():
                for n in names:
                    for what, want, got in _readings(bs, s, c, robot, n):
                        assert want.tobytes() == got.tobytes(), (step, c, robot, n, what, want, got)
                        seen["nan"] += int(np.isnan(got).any())
            seen["speed"] += math.isfinite(s.robot("rover").device("gps").speed)
            seen["turn"] += bool(abs(s.robot("rover").device("plain_gyro").values[2]) > 1.0)
            seen["jolt"] += bool(abs(s.robot("rover").device("plain_acc").values[0]) > 1.0)
    # ramps, disabled axes, speeds, turns and accelerations (wheel changes, the move, the reset)
    assert seen["tilted"] > 50 and seen["nan"] > 0 and seen["speed"] > 100 and seen["turn"] > 100 and seen["jolt"] > 3
    # the noise is each copy's own: the same device reads differently in different copies
    gps = bs.value(bs.device("scout", "gps"))
    assert len({row.tobytes() for row in gps}) == len(seeds)


def _flat(yaws: list[float], translation=(1.0, 2.0, 0.0)) -> wm.World:
    """A robot with plain devices (no noise, no table) at a height of 0, turned by each yaw in turn."""
    devices = [{"device": "GPS", "name": "gps", "pose": {"translation": [0.02, -0.01, 0.05]}},
               {"device": "Compass", "name": "compass"},
               {"device": "InertialUnit", "name": "imu"}]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "gps_reference": [100.0, -20.0, 5.0], "contact": False},
        "robots": [{"name": "bot", "pose": {"translation": list(translation), "rotation": [0, 0, 1, yaws[0]]},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": devices}]})


def test_known_headings_give_the_closed_form_compass_inertial_unit_and_gps_readings():
    """Copy c turned to yaw ψ_c (Rz(ψ) about up): the compass reads north in the robot frame,
    (sin ψ, cos ψ, 0); the inertial unit (0, 0, ψ); the GPS the mount point R·t + p plus the
    world's gps_reference. At ψ = 0 all of it is exact; driving straight at v, the GPS speed is v
    and its speed vector v·(cos ψ, sin ψ, 0)."""
    yaws = [0.0, 0.5, -1.2, 2.9, -3.0]
    bs = BatchedSimulation(_world_model_loaded(_flat(yaws)), len(yaws))
    for c, yaw in enumerate(yaws):
        bs.set_pose(c, 0, rotation=[0, 0, 1, yaw])
    for name in ("gps", "compass", "imu"):
        bs.enable(bs.device("bot", name), 8)
    bs.step()
    compass = bs.value(bs.device("bot", "compass"))
    rpy = bs.value(bs.device("bot", "imu"))
    gps = bs.value(bs.device("bot", "gps"))
    assert compass[0].tolist() == [0.0, 1.0, 0.0] and rpy[0].tolist() == [0.0, 0.0, 0.0]
    assert gps[0].tolist() == [1.0 + 0.02 + 100.0, 2.0 - 0.01 - 20.0, 0.05 + 5.0]
    for c, yaw in enumerate(yaws):
        s, co = math.sin(yaw), math.cos(yaw)
        np.testing.assert_allclose(compass[c], [s, co, 0.0], rtol=0, atol=1e-15)
        np.testing.assert_allclose(rpy[c], [0.0, 0.0, yaw], rtol=0, atol=1e-15)
        np.testing.assert_allclose(gps[c], [1.0 + 0.02 * co + 0.01 * s + 100.0, 2.0 + 0.02 * s - 0.01 * co - 20.0,
                                            5.05], rtol=0, atol=1e-12)
    # straight ahead at 4 rad/s on 5 cm wheels: 0.2 m/s along the heading
    bs.set_wheels(0, np.full(len(yaws), 4.0), np.full(len(yaws), 4.0))
    bs.run(3)
    ref = bs.device("bot", "gps")
    np.testing.assert_allclose(bs.reading(ref, "speed"), 0.2, rtol=1e-12)
    want = np.stack([0.2 * np.cos(yaws), 0.2 * np.sin(yaws), np.zeros(len(yaws))], axis=1)
    np.testing.assert_allclose(bs.reading(ref, "speed_vector"), want, rtol=0, atol=1e-12)


def test_an_altimeter_reads_the_local_reference_altitude_as_the_single_simulation():
    """In local coordinates the altimeter adds the gps_reference's up component (Webots'
    WbAltimeter): every copy, bit for bit the single simulation, and the closed form."""
    w = _flat([0.0, 1.0], translation=(1.0, 2.0, 0.25))
    robot = w.robots[0].model_copy(update={"devices": [*w.robots[0].devices, wm.Altimeter(device="Altimeter", name="alt")]})
    w = w.model_copy(update={"robots": [robot]})
    bs = BatchedSimulation(_world_model_loaded(w), 2)
    bs.enable(bs.device("bot", "alt"), 8)
    sim = Simulation(w)
    sim.device("bot/alt").enable(8)
    bs.step()
    sim.step()
    assert sim.device("bot/alt").value == 0.25 + 5.0
    assert bs.value(bs.device("bot", "alt")).tolist() == [0.25 + 5.0] * 2


def _world_model_loaded(w: wm.World) -> LoadedWorld:
    return LoadedWorld(world=w, source="<test>", base_dir=Path.cwd())


def _rotations(n: int, rng: np.random.Generator) -> np.ndarray:
    """Random rotations, and half turns about each axis and between axes (Shepperd's four branches)."""
    qs = list(rng.standard_normal((n, 4)))
    qs += [np.array(q, dtype=float) for q in ([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 1, 0, 0.01],
                                               [0, 1, 1, 0.02], [1, 0, 1, 0.0], [0, 0, 0, 1])]
    return np.array([quaternion_matrix(q) for q in qs])


@pytest.mark.parametrize("axes", ["ENU", "NUE"])
def test_the_stacked_orientation_formulas_are_the_single_models_bit_for_bit(axes):
    """matrix_quaternions, inertial_quaternions (noise, every disabled-axis combination, resolution)
    and roll_pitch_yaw in both conventions over many rotations: element for element the bits of
    poses.matrix_quaternion, orientation.inertial_quaternion and orientation.roll_pitch_yaw."""
    rng = np.random.default_rng(4)
    R = _rotations(3000, rng)
    k = len(R)
    q = kin.matrix_quaternions(R)
    want_q = np.array([matrix_quaternion(r) for r in R])
    assert q.tobytes() == want_q.tobytes()
    noise = np.where(rng.random(k) < 0.5, 0.02, 0.0)
    gauss = rng.standard_normal((k, 3))
    x, y, z = (rng.random(k) < 0.7 for _ in range(3))
    res = np.where(rng.random(k) < 0.3, 0.001, -1.0)
    got = kin.inertial_quaternions(want_q, gauss, noise, x, y, z, res)
    for i in range(k):
        stream = _Replay(gauss[i])
        want = orient.inertial_quaternion(want_q[i], noise=float(noise[i]), rng=stream if noise[i] else None,  # type: ignore[arg-type]
                                          x_axis=bool(x[i]), y_axis=bool(y[i]), z_axis=bool(z[i]),
                                          resolution=float(res[i]))
        assert want.tobytes() == got[i].tobytes(), i
    rpy = kin.roll_pitch_yaw(got, axes)
    assert rpy.tobytes() == np.array([orient.roll_pitch_yaw(g, axes) for g in got]).tobytes()
    assert (~(x & y & z)).sum() > 500 and (noise > 0).sum() > 500 and (res > 0).sum() > 500


class _Replay:
    """A stand-in random stream giving three given normals."""

    def __init__(self, values: np.ndarray):
        self.values = values

    def standard_normal(self, count: int) -> np.ndarray:
        assert count == 3
        return self.values.copy()


def _spinner(gravity: float = 9.81) -> wm.World:
    """A robot on a flat floor with a gyro and an accelerometer at its centre, a gyro tilted on its
    mount and an accelerometer 5 cm ahead of the centre (no noise, no table)."""
    devices = [{"device": "Gyro", "name": "gyro"}, {"device": "Accelerometer", "name": "acc"},
               {"device": "Gyro", "name": "tilted_gyro", "pose": {"rotation": [1, 0, 0, math.pi / 2]}},
               {"device": "Accelerometer", "name": "ahead", "pose": {"translation": [0.05, 0.0, 0.0]}}]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "gravity": gravity, "contact": False},
        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": [10.0, 10.0]}}],
        "robots": [{"name": "bot", "pose": {"translation": [0.5, -0.2, 0.0], "rotation": [0, 0, 1, 0.4]},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": devices}]})


def test_a_robot_turning_in_place_reads_its_rate_and_at_rest_reads_gravity():
    """Copy c turns in place at ω_c = r·2u/axle (wheels -u, +u): the gyro reads (0, 0, ω) (x and y
    exactly 0, z to the model's rounding), the gyro turned a quarter about x (its y axis is the world's
    up) reads (0, ω, 0) up to rounding; the accelerometer at the
    centre reads (0, 0, g), the one 5 cm ahead the second difference of a circle, 2r(cos δ - 1)/dt²
    along (cos δ, -sin δ) in its frame (δ = ω·dt), plus g on z. At rest both read (0, 0, g) exactly,
    g the world's gravity (3.71 here); the first reading after enable assumes rest."""
    speeds = [0.0, 1.0, -2.5, 6.0]
    bs = BatchedSimulation(_world_model_loaded(_spinner(3.71)), len(speeds))
    for name in ("gyro", "acc", "tilted_gyro", "ahead"):
        bs.enable(bs.device("bot", name), 8)
    u = np.array(speeds)
    bs.set_wheels(0, -u, u)
    bs.step()
    for name in ("acc", "ahead"):                      # one pose after enable: rest
        assert bs.value(bs.device("bot", name)).tolist() == [[0.0, 0.0, 3.71]] * len(speeds)
    dt = 0.008
    for _ in range(5):
        bs.step()
        omega = 0.05 * 2.0 * u / 0.2
        gyro = bs.value(bs.device("bot", "gyro"))
        assert (gyro[:, :2] == 0.0).all() and gyro[0].tolist() == [0.0, 0.0, 0.0]
        np.testing.assert_allclose(gyro[:, 2], omega, rtol=1e-9, atol=0)
        np.testing.assert_allclose(bs.value(bs.device("bot", "tilted_gyro")),
                                   np.stack([0 * omega, omega, 0 * omega], axis=1), rtol=0, atol=1e-9)
        assert bs.value(bs.device("bot", "acc")).tolist() == [[0.0, 0.0, 3.71]] * len(speeds)
        d = omega * dt
        k = 2.0 * 0.05 * (np.cos(d) - 1.0) / dt ** 2
        want = np.stack([k * np.cos(d), -k * np.sin(d), np.full(len(d), 3.71)], axis=1)
        np.testing.assert_allclose(bs.value(bs.device("bot", "ahead")), want, rtol=0, atol=1e-9)
    # ≈ -ω²r towards the centre: 3 rad/s at 5 cm, a real centripetal pull (not a rounding residue)
    assert bs.value(bs.device("bot", "ahead"))[3, 0] == pytest.approx(-3.0 ** 2 * 0.05, rel=1e-3)
    sim = Simulation(_world_model_loaded(_spinner()))                  # the single model agrees at rest
    acc = sim.robot("bot").device("acc")
    acc.enable(8)
    sim.run(4)
    assert acc.values.tolist() == [0.0, 0.0, 9.81]


def _rotation_pairs(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Rotation pairs: random, equal, turned by tiny angles (below and above 1e-6 rad), by about
    and exactly half a turn, about each axis."""
    a = _rotations(800, rng)
    b = _rotations(800, rng)
    pairs = [(a, b), (a, a.copy())]
    for angle in (1e-9, 5e-7, 2e-6, 1e-3, 0.5, math.pi - 1e-7, math.pi):
        axes = rng.standard_normal((len(a), 3))
        turn = np.array([quaternion_matrix([*(ax / np.linalg.norm(ax) * math.sin(angle / 2)), math.cos(angle / 2)])
                         for ax in axes])
        pairs.append((a, np.matmul(a, turn)))
    return np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])


def test_the_c_passes_are_the_math_path_and_the_single_models_bit_for_bit():
    """The helper's passes (packets.c, batched kinematic devices) against the ``math`` fallback and
    the single models element by element: the gyro's rate of every rotation pair (equal, tiny,
    large and half turns), roll/pitch/yaw in both conventions, the inertial unit's noise and
    disabled-axis turns, the GPS correlation ratios (0, 1, a zero exponent included)."""
    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(11)
    r0, r1 = _rotation_pairs(rng)
    got = kin.angular_velocities(r0, r1, 0.016)
    assert got.tobytes() == kin.angular_velocities(r0, r1, 0.016, native=False).tobytes()
    assert got.tobytes() == np.array([motion_math.angular_velocity(a, b, 0.016) for a, b in zip(r0, r1)]).tobytes()
    assert (np.abs(got).max(axis=1) == 0.0).sum() >= 800                 # the equal pairs read 0
    q = kin.matrix_quaternions(_rotations(2000, rng))
    k = len(q)
    noise = np.where(rng.random(k) < 0.5, 0.02, 0.0)
    gauss = rng.standard_normal((k, 3))
    x, y, z = (rng.random(k) < 0.6 for _ in range(3))
    res = np.where(rng.random(k) < 0.3, 0.001, -1.0)
    out = kin.inertial_quaternions(q, gauss, noise, x, y, z, res)
    assert out.tobytes() == kin.inertial_quaternions(q, gauss, noise, x, y, z, res, native=False).tobytes()
    for axes in ("ENU", "NUE"):
        for quats in (q, out, np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.7071067811865476, 0.0, 0.7071067811865476],
                                        [math.nan, 0.0, 0.0, 1.0], [0.0, -0.0, -0.0, 1.0]])):
            rpy = kin.roll_pitch_yaw(quats, axes)
            assert rpy.tobytes() == kin.roll_pitch_yaw(quats, axes, native=False).tobytes()
            assert rpy.tobytes() == np.array([orient.roll_pitch_yaw(v, axes) for v in quats]).tobytes()
    corr = np.array([0.0, 1.0, 0.7, 0.7, 0.3, 1e-300, 0.999])
    expo = np.array([0.032, 0.5, 0.0, 0.016, 2.5, 0.048, 1000.0])
    ratios = kin.correlation_ratios(corr, expo)
    assert ratios.tobytes() == kin.correlation_ratios(corr, expo, native=False).tobytes()
    assert ratios[:3].tolist() == [0.0, 1.0, 1.0]
    # inputs the Python way treats specially are left to it: the helper declines them
    assert packets.half_angles(np.array([[math.inf, 0.0, 0.0, 1.0]])) is None
    assert packets.correlation_ratios(np.array([-0.5]), np.array([1.0])) is None


def test_what_stays_refused_is_said_in_one_line():
    """A kind without a value (an LED): one line naming the device and why, when asked for (device,
    check_observable) and before anything is built (the world-level check); in a WGS84 world GPS,
    compasses, gyros, accelerometers, inertial units and altimeters are measured."""
    lw = load_world(WORLD)
    w = lw.world
    robots = [r.model_dump(mode="json", exclude_none=True) for r in w.robots]
    robots[0]["devices"] += [{"device": "Altimeter", "name": "altimeter"}, {"device": "LED", "name": "led"}]
    wgs = wm.World.model_validate({**w.model_dump(mode="json", exclude_none=True), "robots": robots,
                                   "world_info": {**w.world_info.model_dump(mode="json"),
                                                  "gps_coordinate_system": "WGS84",
                                                  "gps_reference": [46.5, 6.6, 400.0]}})
    bs = BatchedSimulation(wgs, 2, base_dir=lw.base_dir)
    for name, kind in (("gps", "GPS"), ("compass", "Compass"), ("gyro", "Gyro"), ("acc", "Accelerometer"),
                       ("altimeter", "Altimeter")):
        assert bs.device("rover", name).kind == kind
    check_observable(wgs, "rover", ["gps", "compass", "gyro", "acc", "imu", "altimeter"])
    want = (r"^robot 'rover': device 'led' is a LED; the batched simulation measures "
            r".*GPS, Compass, InertialUnit, Gyro, Accelerometer(, [A-Za-z]+)* \(use Simulation\)$")
    for call in (lambda: check_observable(wgs, "rover", ["compass", "led"]), lambda: bs.device("rover", "led")):
        with pytest.raises(BatchedError, match=want):
            call()


gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402

OBSERVED = {"gps": 32, "compass": 16, "imu": 16, "flat_imu": 32, "gyro": 16, "acc": 32, "plain_gyro": 16,
            "plain_acc": 16}


def _task() -> Task:
    return Task(robot="rover", observations=OBSERVED, control_period_ms=32, max_steps=25)


def test_the_vector_env_observes_them_as_the_single_env_and_passes_the_checker():
    """A task observing a noisy GPS, a compass with a table and a disabled axis, two inertial units,
    gyros and accelerometers with and without tables: (3,) float32 boxes (a table's output column;
    without one, ±π/dt for a gyro and the world's coordinate limits' bound for an accelerometer);
    every sub-env of the vector env equals the single env (rebuilt
    Simulation, and the one-copy batched engine) with its seed, observations and info bit for bit,
    across autoresets; a sub-env passes Gymnasium's checker without a warning."""
    n = 3
    venv = SensoriumVectorEnv(WORLD, _task(), n)
    space = venv.single_observation_space
    assert {k: space[k].shape for k in OBSERVED} == dict.fromkeys(OBSERVED, (3,))
    assert space["imu"].high.tolist() == np.array([math.pi, math.pi / 2, math.pi], dtype=np.float32).tolist()
    assert space["compass"].low.tolist() == [-100.0] * 3 and space["compass"].high.tolist() == [100.0] * 3
    assert space["gyro"].high.tolist() == [40.0] * 3 and space["acc"].low.tolist() == [-100.0] * 3
    assert space["plain_gyro"].high.tolist() == [np.float32(math.pi / 0.016)] * 3
    assert space["plain_acc"].low.tolist() == [np.float32(-(4 * math.sqrt(3) * 1e5 / 0.016 ** 2 + 9.81))] * 3
    singles = [SensoriumEnv(WORLD, _task(), engine=e) for e in ("simulation", "batched", "simulation")]
    assert [e.engine for e in singles] == ["simulation", "batched", "simulation"]
    obs = _reset_both(venv, singles, 9)
    assert obs["compass"][:, 1].tolist() == [-100.0] * n          # the disabled y axis: the box's low bound
    assert obs["acc"][:, 1].tolist() == [-100.0] * n
    rng = np.random.default_rng(3)
    done = np.zeros(n, dtype=bool)
    ended = 0
    for t in range(60):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        resets, vobs = _step_both(venv, singles, a, done, t)
        ended += resets
    assert ended >= n                                           # autoresets happened
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(venv.sub_env(1), skip_render_check=True)            # (no registered id: no spec to remake)
        check_env(SensoriumVectorEnv(WORLD, _task(), 2, flatten=True).sub_env(0), skip_render_check=True)
    venv.close()


def test_the_envs_observe_a_wgs84_gps_alike():
    """In a WGS84 world the vector env runs a GPS too (latitude, longitude, altitude): every sub-env
    equals the single env (rebuilt Simulation, and the batched engine "auto" now picks) with its
    seed, bit for bit, across autoresets; the readings are near the reference (46.5°, 6.6°)."""
    lw = load_world(WORLD)
    w = lw.world
    wgs = LoadedWorld(world=w.model_copy(update={"world_info": w.world_info.model_copy(
        update={"gps_coordinate_system": "WGS84", "gps_reference": (46.5, 6.6, 400.0)})}),
        source=lw.source, base_dir=lw.base_dir)
    n = 2
    venv = SensoriumVectorEnv(wgs, _task(), n)
    singles = [SensoriumEnv(wgs, _task(), engine=e) for e in ("simulation", "auto")]
    assert [e.engine for e in singles] == ["simulation", "batched"]
    obs = _reset_both(venv, singles, 2)
    assert (np.abs(obs["gps"][:, :2] - [46.5, 6.6]) < 1e-4).all()
    assert venv.single_observation_space["gps"].low[:2].tolist() == [-90.0, -360.0]
    rng = np.random.default_rng(8)
    done = np.zeros(n, dtype=bool)
    ended = 0
    for t in range(40):
        ended += _step_both(venv, singles, rng.uniform(-1, 1, (n, 2)).astype(np.float32), done, t)[0]
    assert ended >= n
    venv.close()


def test_a_wgs84_longitude_past_the_antimeridian_is_observed_as_read():
    """East of the antimeridian a WGS84 GPS reads longitudes past 180 (unwrapped, as in Webots): the
    observation keeps them (its box allows +-360), the same in both envs -- clipped to 180, a robot
    there would silently read the meridian."""
    lw = load_world(WORLD)
    w = lw.world
    moved = [r.model_copy(update={"pose": r.pose.model_copy(update={"translation": (
        r.pose.translation[0] + 200.0, *r.pose.translation[1:])})}) for r in w.robots]   # 200 m east
    wgs = LoadedWorld(world=w.model_copy(update={"robots": moved, "world_info": w.world_info.model_copy(
        update={"gps_coordinate_system": "WGS84", "gps_reference": (10.0, 179.999, 0.0)})}),
        source=lw.source, base_dir=lw.base_dir)
    venv = SensoriumVectorEnv(wgs, _task(), 1)
    single = SensoriumEnv(wgs, _task())
    obs = _reset_both(venv, [single], 1)
    lon = float(obs["gps"][0, 1])
    assert 180.0005 < lon < 180.003      # 200 m east at 10 deg N: ~0.00183 deg past 179.999
    venv.close()
