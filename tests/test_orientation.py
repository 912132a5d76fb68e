"""InertialUnit and Compass against closed-form answers: at rest, a constant turn, a supervisor pose
on a slope, both coordinate systems; Webots' timing, noise, resolution and disabled axes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import orientation as om
from sensorium.server.devices.lookup import LookupTable
from sensorium.server.sim.simulation import Simulation

R_WHEEL, AXLE = 0.02, 0.1


def make(imu=None, compass=None, world_info=None, pose=None):
    data = {"world_info": {"basic_time_step": 16, "contact": False, **(world_info or {})},
            "robots": [{"name": "r", "pose": pose or {"translation": [0.0, 0.0, 0.0]},
                        "differential_drive": {"wheel_radius": R_WHEEL, "axle_length": AXLE, "max_wheel_speed": 100},
                        "devices": [{"device": "InertialUnit", "name": "imu", **(imu or {})},
                                    {"device": "Compass", "name": "compass", **(compass or {})}]}]}
    sim = Simulation(wm.World.model_validate(data))
    sim.device("r/imu").enable(16)
    sim.device("r/compass").enable(16)
    return sim


def test_nan_before_the_first_value_then_identity_at_rest():
    sim = make()
    imu, compass = sim.device("r/imu"), sim.device("r/compass")
    assert np.isnan(imu.quaternion).all() and np.isnan(imu.roll_pitch_yaw).all() and np.isnan(compass.values).all()
    sim.step()
    np.testing.assert_array_equal(imu.quaternion, [0.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(imu.roll_pitch_yaw, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(compass.values, [0.0, 1.0, 0.0])          # ENU: north is +y


def test_constant_turn_yaw_and_compass():
    sim = make()
    r = sim.robot("r")
    for name, w in (("left wheel motor", -2.0), ("right wheel motor", 2.0)):   # spin in place
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)
    omega = R_WHEEL * 4.0 / AXLE                       # 0.8 rad/s
    sim.run(50)                                        # t = 0.8 s
    yaw = omega * 0.8
    imu, compass = sim.device("r/imu"), sim.device("r/compass")
    np.testing.assert_allclose(imu.roll_pitch_yaw, [0.0, 0.0, yaw], atol=1e-12)
    np.testing.assert_allclose(imu.quaternion, [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)], atol=1e-12)
    # north (0, 1, 0) seen from a frame turned by yaw about z: (sin yaw, cos yaw, 0)
    np.testing.assert_allclose(compass.values, [math.sin(yaw), math.cos(yaw), 0.0], atol=1e-12)


def test_supervisor_pose_on_a_slope():
    sim = make(imu={"pose": {"rotation": [0, 0, 1, 0.3]}})      # the unit is mounted turned by 0.3 rad
    pitch, roll = 0.4, -0.2
    # robot rotation Rz(0) Ry(pitch) Rx(roll) as a quaternion (x, y, z, w)
    qy = [0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2)]
    qx = [math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2)]
    q = om.quaternion_multiply(qy, qx)
    sim.robot("r").set_pose([1.0, 2.0, 0.3], quaternion=list(q))
    sim.step()
    imu = sim.device("r/imu")
    mount = [0.0, 0.0, math.sin(0.15), math.cos(0.15)]
    expected = om.quaternion_multiply(q, mount)
    np.testing.assert_allclose(imu.quaternion, expected, atol=1e-12)
    # the robot alone (a unit mounted straight) reads its roll and pitch exactly
    sim2 = make()
    sim2.robot("r").set_pose([1.0, 2.0, 0.3], quaternion=list(q))
    sim2.step()
    np.testing.assert_allclose(sim2.device("r/imu").roll_pitch_yaw, [roll, pitch, 0.0], atol=1e-12)
    # the compass: Rᵀ·(0, 1, 0) with R = Ry(pitch) Rx(roll)
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    R = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    np.testing.assert_allclose(sim2.device("r/compass").values, R.T @ [0, 1, 0], atol=1e-12)


def test_nue_world():
    sim = make(world_info={"coordinate_system": "NUE"})
    sim.robot("r").set_pose(None, [0.0, 1.0, 0.0, 0.5])        # a turn of 0.5 rad about up (+y)
    sim.step()
    imu, compass = sim.device("r/imu"), sim.device("r/compass")
    np.testing.assert_allclose(imu.roll_pitch_yaw, [0.0, 0.0, 0.5], atol=1e-12)   # Webots' NUE yaw about y
    # north is +x; seen from the turned frame: Ry(0.5)ᵀ·(1, 0, 0) = (cos, 0, sin)
    np.testing.assert_allclose(compass.values, [math.cos(0.5), 0.0, math.sin(0.5)], atol=1e-12)


def test_enu_formulas_match_a_direct_euler_construction():
    rng = np.random.default_rng(3)
    for _ in range(200):
        roll, yaw = rng.uniform(-math.pi, math.pi, 2)
        pitch = rng.uniform(-1.5, 1.5)
        q = om.quaternion_multiply(om.quaternion_multiply([0, 0, math.sin(yaw / 2), math.cos(yaw / 2)],
                                                          [0, math.sin(pitch / 2), 0, math.cos(pitch / 2)]),
                                   [math.sin(roll / 2), 0, 0, math.cos(roll / 2)])
        np.testing.assert_allclose(om.roll_pitch_yaw(q, "ENU"), [roll, pitch, yaw], atol=1e-9)


def test_lookup_table_resolution_axes_and_noise():
    sim = make(compass={"lookup_table": [[-1, -100, 0], [1, 100, 0]], "z_axis": False, "resolution": 7},
               imu={"resolution": 0.25})
    sim.robot("r").set_pose(None, [0, 0, 1, 0.5])
    sim.step()
    c = sim.device("r/compass").values
    # 100·sin 0.5 = 47.94 → 49 (trunc(6.85 + 0.5) · 7); 100·cos 0.5 = 87.76 → 91; z disabled: NaN
    assert c[0] == 49.0 and c[1] == 91.0 and math.isnan(c[2])
    np.testing.assert_array_equal(sim.device("r/imu").quaternion, [0.0, 0.0, 0.25, 1.0])
    # noise: σ = noise·π per angle, one stream per device (reproducible)
    a = make(imu={"noise": 0.01})
    b = make(imu={"noise": 0.01})
    yaws = []
    for _ in range(1000):
        a.step()
        b.step()
        yaws.append(a.device("r/imu").roll_pitch_yaw[2])
    np.testing.assert_array_equal(a.device("r/imu").quaternion, b.device("r/imu").quaternion)
    assert np.std(yaws) == pytest.approx(0.01 * math.pi, rel=0.1)


def test_disabled_imu_axis_drops_part_of_the_rotation():
    q = om.inertial_quaternion([0.0, 0.0, math.sin(0.25), math.cos(0.25)], z_axis=False)   # zAxis → axis y
    np.testing.assert_allclose(q, [0.0, 0.0, math.sin(0.25), math.cos(0.25)], atol=1e-15)
    q = om.inertial_quaternion([0.0, 0.0, math.sin(0.25), math.cos(0.25)], y_axis=False)   # yAxis → axis z
    np.testing.assert_allclose(q, [0.0, 0.0, 0.0, 1.0], atol=1e-15)


def test_compass_lookup_identity_when_empty():
    v = om.compass_values(np.eye(3), "ENU", LookupTable([]), None)
    np.testing.assert_array_equal(v, [0.0, 1.0, 0.0])


def test_services_topics_and_step_values():
    sim = make(imu={"noise": 0.0})
    core = Core(sim)
    assert {"/r/imu/get_roll_pitch_yaw", "/r/imu/get_quaternion", "/r/imu/get_noise", "/r/compass/get_values",
            "/r/compass/get_lookup_table"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/imu/quaternion"] == msgs.IMU and types["/r/compass/values"] == msgs.MAGNETIC_FIELD
    sim.robot("r").set_pose(None, [0, 0, 1, 0.5])
    sim.step()
    imu = core.topics.controls["r/imu"]
    body = msgs.validate(msgs.IMU, core.topics.build(imu, "quaternion", sim.time_ms))
    assert (body.orientation.z, body.orientation.w) == pytest.approx((math.sin(0.25), math.cos(0.25)), abs=1e-15)
    cov = np.frombuffer(body.angular_velocity_covariance, "<f8")
    assert cov[0] == -1.0                                  # REP 145: not provided
    field = msgs.validate(msgs.MAGNETIC_FIELD, core.topics.build(core.topics.controls["r/compass"], "values",
                                                                  sim.time_ms))
    assert field.magnetic_field.x == pytest.approx(math.sin(0.5), abs=1e-15)
    step = core.topics.reading(imu)
    assert step["quaternion"] == [body.orientation.x, body.orientation.y, body.orientation.z, body.orientation.w]
    assert step["roll_pitch_yaw"][2] == pytest.approx(0.5, abs=1e-15)


def test_messages_export_to_ros2():
    from sensorium.server.recording.export import to_ros, to_rosbags, typestore_for
    sim = make(imu={"noise": 0.001})
    core = Core(sim)
    sim.step()
    store = typestore_for("humble")
    for path, item, typ in (("r/imu", "quaternion", msgs.IMU), ("r/compass", "values", msgs.MAGNETIC_FIELD)):
        body = core.topics.build(core.topics.controls[path], item, sim.time_ms)
        msg = to_rosbags(store, typ, to_ros(store, typ, body))
        assert type(msg).__name__ in ("sensor_msgs__msg__Imu", "sensor_msgs__msg__MagneticField")
    imu = to_rosbags(store, msgs.IMU, to_ros(store, msgs.IMU, core.topics.build(core.topics.controls["r/imu"],
                                                                                "quaternion", sim.time_ms)))
    assert imu.orientation.w == sim.device("r/imu").quaternion[3]
    assert imu.orientation_covariance[0] == pytest.approx((0.001 * math.pi) ** 2)


def _webots_to_quaternion(m: np.ndarray) -> np.ndarray:
    """Webots' WbMatrix3::toQuaternion as its branches compute it, returned as (x, y, z, w)."""
    m = m.reshape(-1)
    tr = m[0] + m[4] + m[8]
    if tr >= 0.0:
        s = 2.0 * math.sqrt(tr + 1.0)
        return np.array([(m[7] - m[5]) / s, (m[2] - m[6]) / s, (m[3] - m[1]) / s, 0.25 * s])
    if m[0] > m[4] and m[0] > m[8]:
        s = 2.0 * math.sqrt(1.0 + m[0] - m[4] - m[8])
        return np.array([0.25 * s, (m[1] + m[3]) / s, (m[6] + m[2]) / s, (m[7] - m[5]) / s])
    if m[4] > m[8]:
        s = 2.0 * math.sqrt(1.0 + m[4] - m[8] - m[0])
        return np.array([(m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s, (m[2] - m[6]) / s])
    s = 2.0 * math.sqrt(1.0 + m[8] - m[0] - m[4])
    return np.array([(m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s, (m[3] - m[1]) / s])


@pytest.mark.parametrize("axis, angle", [((0, 0, 1), -2.97), ((0, 0, 1), 2.5), ((0, 0, 1), -1.0), ((1, 0, 0), -2.2),
                                         ((0, 1, 0), -2.6), ((1, 2, -1), -2.9), ((-1, 1, 3), 3.1), ((0, 0, 1), 0.0)])
def test_quaternion_has_webots_sign_and_resolution_rounds_those_components(axis, angle):
    """Webots' quaternion is WbMatrix3::toQuaternion's: w > 0 for a turn up to 120°, else the
    component of the largest diagonal term > 0 (a robot yawed by -170° reads z > 0, w < 0). It was
    always given w >= 0 here: the opposite sign there, and with a resolution (components rounded by
    discretize, asymmetric for negatives) another rotation, so other roll/pitch/yaw: -170° read
    -163.8° at resolution 0.1, where Webots reads 180°. The batched simulation reads the same."""
    from sensorium.server.devices.lookup import quantize_sensor
    from sensorium.server.sim.batched import BatchedSimulation
    from sensorium.server.world.poses import axis_angle_matrix

    rot = np.asarray(axis_angle_matrix(axis, angle))
    for res in (-1.0, 0.1):
        data = {"world_info": {"basic_time_step": 16, "contact": False},
                "robots": [{"name": "r", "pose": {"rotation": [*axis, angle]},
                            "devices": [{"device": "InertialUnit", "name": "imu", "resolution": res}]}]}
        world = wm.World.model_validate(data)
        sim, bs = Simulation(world), BatchedSimulation(world, 1)
        sim.device("r/imu").enable(16)
        bs.enable(bs.device("r", "imu"), 16)
        sim.step()
        bs.step()
        want = _webots_to_quaternion(rot)
        if res > 0:
            want = np.array([quantize_sensor(float(v), res) for v in want])
        imu = sim.device("r/imu")
        np.testing.assert_allclose(imu.quaternion, want, atol=1e-12)
        x, y, z, w = want
        yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        assert imu.roll_pitch_yaw[2] == pytest.approx(yaw, abs=1e-12)
        assert bs.reading(bs.device("r", "imu"), "quaternion")[0].tobytes() == imu.quaternion.tobytes()
    if (axis, angle) == ((0, 0, 1), -2.97):
        assert imu.quaternion[2] == 1.0 and imu.quaternion[3] == 0.0 and imu.roll_pitch_yaw[2] == pytest.approx(math.pi)
