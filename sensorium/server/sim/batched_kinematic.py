"""GPS, Compass, InertialUnit, Gyro, Accelerometer, TouchSensor (bumper) and Altimeter in the
batched simulation: every copy's due devices of a kind measured together, from the copies'
end-of-step poses (a bumper: from the copy's contact state, ``pressing``), bit for bit what the
single simulation's devices (sim/sensors.py, on the pure models of devices/gps.py,
devices/orientation.py and devices/motion_sensors.py) give.

How the bits are kept:

* float64 ``+ - * / sqrt`` are exactly rounded alike in numpy and in Python, so those are done on
  whole arrays in the single models' order of operations;
* the small products the single models leave to numpy's ``@`` (Pose.compose's 3x3 products, a
  compass's ``Rᵀ·north``, a gyro's ``R₀ᵀ·R₁``, an accelerometer's ``Rᵀ·(a + g·up)``, a norm's dot
  product) go through ``np.matmul`` on stacks of the same 3x3 / 3-vector operands: numpy hands each
  item to the same BLAS call as the 2-D product, so the summation order (and any fused
  multiply-add) is the same;
* ``atan2``, ``asin``, ``acos``, ``sin``, ``cos`` and ``pow`` are libm's per element, never numpy's
  vectorised ufuncs, whose SIMD routines may round differently on this machine (``x ** 2``
  included: numpy's scalar power calls libm's ``pow``, which is not ``x * x``): in one C pass per
  kind where the packets helper is built (raycast/packets.c, "batched kinematic devices": the
  very functions Python's ``math`` calls, the arithmetic around them element by element), else
  through ``math`` and Python floats (``native=False``, and ``SENSORIUM_PACKETS=0``);
* each device's noise comes from its own stream (``NoiseStreams``), taken in the order the single
  model draws it.

A gyro or an accelerometer differences the device's world poses after the last basic steps since
it was enabled (_MotionSensor in sim/sensors.py): the copies' end-of-step robot poses of the last
two steps are kept for every slot, and per device the robot's pose when it was enabled and how
many poses it has seen since (1 at ``enable``, at most 3), so its poses are composed only when it
is due. A device riding a joint (``on_joint``) takes its copy's local pose from batched_joints.py;
a gyro's or accelerometer's local poses at those times are kept per copy beside the robot's.

A bumper keeps a touch until it is read, as the single TouchSensor (WbTouchSensor's flag): per copy
and bumper a ``touched`` flag, or-ed after each step where an armed bumper (enabled at least once
since the copy was built or reset) is not due and has not touched yet -- those (copy, bumper) pairs
measured together by the due bumpers' own test -- and cleared by its reading, which is 1 when the
flag was set. Nothing of this runs while every bumper enabled is due every step and none was
disabled after an enable (``latching``).

A GPS in a WGS84 world adds the reference's UTM east / north and altitude (computed once, by the
single model's call) and reads its rows back to latitude / longitude by the single model's inverse
UTM series, called row by row (:func:`wgs84_positions`).

Not here: a force or force-3d TouchSensor (NaN without physics: refused with one line). ENU and NUE
worlds: the roll / pitch / yaw conventions of both are here (:func:`roll_pitch_yaw`), a WGS84 GPS and
an altimeter read east / north / up along the world's axes, tested against the single model.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.devices import gps as gps_math
from sensorium.server.devices import motion_sensors as motion_math
from sensorium.server.devices import orientation as orient
from sensorium.server.devices.lookup import RESOLUTION_OFF
from sensorium.server.raycast import packets
from sensorium.server.sim.contact import EPS, FLOOR, TOUCH, Obstacle, device_pieces, pieces_touch, robot_obstacles
from sensorium.server.sim.scene import primitive_from_model
from sensorium.server.sim.sensors import (
    GPS,
    Accelerometer,
    Altimeter,
    Compass,
    Gyro,
    InertialUnit,
    TouchSensor,
    altitude_offset,
)
from sensorium.server.world.arrays import unique_ints
from sensorium.server.world.poses import pose_from_model

__all__ = ["KINDS", "CLASSES", "SHAPES", "READINGS", "KinematicDevices", "draws_noise", "refusal", "libm_each",
           "libm_cos_sin", "roll_pitch_yaw", "matrix_quaternions", "inertial_quaternions", "angular_velocities",
           "correlation_ratios"]

KINDS = ("GPS", "Compass", "InertialUnit", "Gyro", "Accelerometer", "TouchSensor", "Altimeter")
MOTION = ("Gyro", "Accelerometer")
"""The kinds that read the motion over the last basic steps (their poses tracked every step)."""
CLASSES: dict[str, type] = {"GPS": GPS, "Compass": Compass, "InertialUnit": InertialUnit, "Gyro": Gyro,
                            "Accelerometer": Accelerometer, "TouchSensor": TouchSensor, "Altimeter": Altimeter}
SHAPES = {k: (3,) for k in ("GPS", "Compass", "InertialUnit", "Gyro", "Accelerometer")}
"""The shape of one device's value (``BatchedSimulation.values[kind]`` is (copies, devices, *shape)):
a GPS's position, a compass's north vector, an inertial unit's roll, pitch, yaw, a gyro's angular
velocity, an accelerometer's specific force; a bumper's and an altimeter's value is one number."""
# m: a shaped bumper's broad phase (_bumper_near) keeps pairs this much farther apart than pieces_touch
# could find touching, far above the rounding of placing a piece two ways (turned points, turned disc)
_SLACK = 1e-7
READINGS = {"GPS": ("values", "speed", "speed_vector"), "Compass": ("values",),
            "InertialUnit": ("roll_pitch_yaw", "quaternion"), "Gyro": ("values",), "Accelerometer": ("values",),
            "TouchSensor": ("value",), "Altimeter": ("value",)}
"""What a device of each kind reads (the single simulation's attributes of the same names)."""


def refusal(robot: str, config: Any, world_info: Any) -> str | None:
    """Why the batched simulation does not measure a device of these kinds in this world, or None."""
    if config.device == "TouchSensor" and config.type != "bumper":
        return (f"{robot}/{config.name}: a {config.type} TouchSensor reads NaN without physics; the batched "
                "simulation measures bumpers only (use Simulation)")
    return None


def gps_reference(world_info: Any) -> tuple[np.ndarray, gps_math.Utm | None]:
    """What gps.position adds to a GPS's translation, and the UTM zone its WGS84 values are read
    back in (None in local coordinates): gps_reference itself, or in a WGS84 world the reference
    latitude / longitude as UTM east / north and its altitude (the single model's own call), each
    along its world axis (ENU: x, y, z; NUE: z, x, y)."""
    ref = np.array(world_info.gps_reference, dtype=np.float64)
    if world_info.gps_coordinate_system != "WGS84":
        return ref, None
    utm = gps_math.Utm(float(ref[0]), float(ref[1]))
    north, east = utm.north_east(float(ref[0]), float(ref[1]))
    axes = world_info.coordinate_system
    out = np.empty(3)
    out[axes.index("E")], out[axes.index("N")], out[axes.index("U")] = east, north, float(ref[2])
    return out, utm


def wgs84_positions(utm: gps_math.Utm, p: np.ndarray, axes: str = "ENU") -> np.ndarray:
    """gps.position's last step for rows of world positions (``axes``: which is east, north, up):
    (latitude°, longitude°, altitude) by the single model's inverse UTM series, row by row (its sin,
    tan, pow and friends are libm's through ``math``, whose bits numpy's vectorised routines need not give)."""
    e, n, u = axes.index("E"), axes.index("N"), axes.index("U")
    out = np.empty_like(p)
    for k, row in enumerate(p.tolist()):
        out[k, 0], out[k, 1] = utm.latitude_longitude(row[n], row[e])
        out[k, 2] = row[u]
    return out


def draws_noise(config: Any) -> bool:
    """Whether a device of these kinds ever draws from its noise stream (a compass: its table)."""
    if config.device == "GPS":
        return config.accuracy > 0.0 or config.speed_noise > 0.0
    if config.device == "InertialUnit":
        return config.noise > 0.0
    if config.device == "Altimeter":
        return config.accuracy > 0.0
    return False


def libm_each(fn, *columns: np.ndarray) -> np.ndarray:
    """``fn`` (a ``math`` function, libm's) of each element: the single models' scalar calls (numpy's
    float64 routines may round differently on this machine)."""
    flat = [c.reshape(-1).tolist() for c in columns]
    return np.array(list(map(fn, *flat)), dtype=np.float64).reshape(columns[0].shape)


def libm_cos_sin(a: np.ndarray, native: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(math.cos, math.sin) of each element: libm's, in one C pass where the helper is
    (packets.cos_sin), else through Python floats."""
    got = packets.cos_sin(np.ascontiguousarray(a.reshape(-1))) if native and a.dtype == np.float64 else None
    if got is not None:
        return got[0].reshape(a.shape), got[1].reshape(a.shape)
    return libm_each(math.cos, a), libm_each(math.sin, a)


def correlation_ratios(corr: np.ndarray, exponent: np.ndarray, native: bool = True) -> np.ndarray:
    """gps.position's ``correlation ** (elapsed / 1000)`` (0 for a correlation of 0) per row."""
    got = packets.correlation_ratios(corr, exponent) if native else None
    if got is not None:
        return got
    return np.array([cr ** e if cr != 0.0 else 0.0 for cr, e in zip(corr.tolist(), exponent.tolist())],
                    dtype=np.float64)


def _dots(v: np.ndarray) -> np.ndarray:
    """``v[i] @ v[i]`` per row, through the same BLAS dot product as the 1-D ``@`` of a contiguous
    vector (np.matmul of stacked row and column vectors gives each item to it; BLAS may sum a
    strided vector in another order, so the rows are made contiguous first)."""
    v = np.ascontiguousarray(v)
    return np.matmul(v[:, None, :], v[:, :, None])[:, 0, 0]


def _quantize(v: np.ndarray, res: np.ndarray) -> np.ndarray:
    """lookup.quantize_sensor per row (``res`` (k,), RESOLUTION_OFF: unchanged)."""
    on = res != RESOLUTION_OFF
    if not on.any():
        return v
    r = np.where(on, res, 1.0).reshape((-1,) + (1,) * (v.ndim - 1))
    return np.where(on.reshape(r.shape), np.trunc(v / r + 0.5) * r + 0.0, v)


def matrix_quaternions(m: np.ndarray) -> np.ndarray:
    """poses.matrix_quaternion of each (k, 3, 3) rotation: (k, 4) (x, y, z, w), w >= 0. Shepperd's
    four branches each computed with its operations, the one the scalar code takes kept."""
    m00, m11, m22 = m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]
    tr = m00 + m11 + m22
    with np.errstate(invalid="ignore", divide="ignore"):        # the branches not taken
        s0 = np.sqrt(tr + 1.0) * 2.0
        s1 = np.sqrt(1.0 + m00 - m11 - m22) * 2.0
        s2 = np.sqrt(1.0 + m11 - m00 - m22) * 2.0
        s3 = np.sqrt(1.0 + m22 - m00 - m11) * 2.0
        d21, d02, d10 = m[:, 2, 1] - m[:, 1, 2], m[:, 0, 2] - m[:, 2, 0], m[:, 1, 0] - m[:, 0, 1]
        a01, a02, a12 = m[:, 0, 1] + m[:, 1, 0], m[:, 0, 2] + m[:, 2, 0], m[:, 1, 2] + m[:, 2, 1]
        branches = [  # (w, x, y, z) of each branch
            (0.25 * s0, d21 / s0, d02 / s0, d10 / s0),
            (d21 / s1, 0.25 * s1, a01 / s1, a02 / s1),
            (d02 / s2, a01 / s2, 0.25 * s2, a12 / s2),
            (d10 / s3, a02 / s3, a12 / s3, 0.25 * s3),
        ]
    first = tr > 0.0
    second = ~first & (m00 > m11) & (m00 > m22)
    third = ~first & ~second & (m11 > m22)
    pick = np.where(first, 0, np.where(second, 1, np.where(third, 2, 3)))
    wxyz = np.stack([np.choose(pick, [b[j] for b in branches]) for j in range(4)], axis=1)
    q = wxyz[:, [1, 2, 3, 0]]
    q = q / np.sqrt(_dots(q))[:, None]                   # q /= np.linalg.norm(q)
    return np.where((q[:, 3] < 0.0)[:, None], -q, q)


def _axis_turns(angles: np.ndarray, native: bool = True) -> np.ndarray:
    """The noise turn of orientation.inertial_quaternion for rows of three angles (k, 3): the
    quaternions about x, y, z multiplied in that order, as (4, k) columns."""
    k = len(angles)
    half = angles / 2.0
    c, s = libm_cos_sin(half, native)
    qs = []
    for axis in range(3):
        q = np.zeros((4, k))
        q[axis] = s[:, axis]
        q[3] = c[:, axis]
        qs.append(q)
    return orient.quaternion_multiply(orient.quaternion_multiply(qs[0], qs[1]), qs[2])


def inertial_quaternions(q: np.ndarray, gauss: np.ndarray | None, noise: np.ndarray, x_axis: np.ndarray,
                         y_axis: np.ndarray, z_axis: np.ndarray, resolution: np.ndarray,
                         native: bool = True) -> np.ndarray:
    """orientation.inertial_quaternion of each row: ``q`` (k, 4) world rotations, ``gauss`` (k, 3)
    the standard normals of the rows with ``noise`` != 0 (any value elsewhere), the per-row fields.
    ``native=False``: the libm calls through ``math`` (the helper's fallback)."""
    out = np.array(q, dtype=np.float64)
    noisy = (noise != 0.0).nonzero()[0]
    if len(noisy):
        assert gauss is not None
        angles = noise[noisy, None] * math.pi * gauss[noisy]       # noise * math.pi * G, left to right
        out[noisy] = orient.quaternion_multiply(out[noisy].T, _axis_turns(angles, native)).T
    off = (~(x_axis & y_axis & z_axis)).nonzero()[0]
    if len(off):
        o = out[off]
        half = packets.half_angles(o) if native else None
        if half is None:
            sq = [libm_each(lambda v: v ** 2, o[:, j]) for j in range(3)]  # numpy's scalar ** 2: libm's pow
            half = libm_each(math.atan2, np.sqrt(sq[0] + sq[1] + sq[2]), o[:, 3])
        axis = o[:, :3].copy()
        axis[~x_axis[off], 0] = 0.0                                  # Webots' mapping: y -> z, z -> y
        axis[~y_axis[off], 2] = 0.0
        axis[~z_axis[off], 1] = 0.0
        norm = np.sqrt(_dots(axis))
        zero = norm == 0.0
        cos, sin = libm_cos_sin(half, native)
        with np.errstate(invalid="ignore", divide="ignore"):
            turned = axis / norm[:, None] * sin[:, None]
        o = np.concatenate([turned, cos[:, None]], axis=1)
        o[zero] = (0.0, 0.0, 0.0, 1.0)
        out[off] = o
    out = orient.webots_sign(out)
    return _quantize(out, resolution)


def roll_pitch_yaw(q: np.ndarray, axes: str = "ENU", native: bool = True) -> np.ndarray:
    """orientation.roll_pitch_yaw of each (k, 4) quaternion: (k, 3) roll, pitch, yaw."""
    got = packets.roll_pitch_yaw(q, axes == "NUE") if native else None
    if got is not None:
        return got
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]

    def asin_clamped(v: np.ndarray) -> np.ndarray:     # max(-1, min(1, v)) as Python compares (NaN -> 1)
        return libm_each(lambda a: math.asin(max(-1.0, min(1.0, a))), v)

    if axes == "NUE":
        yaw = libm_each(math.atan2, 2 * y * w - 2 * x * z, 1 - 2 * y * y - 2 * z * z)
        roll = libm_each(math.atan2, 2 * x * w - 2 * y * z, 1 - 2 * x * x - 2 * z * z)
        pitch = asin_clamped(2 * x * y + 2 * z * w)
    else:
        roll = libm_each(math.atan2, 2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
        pitch = asin_clamped(2.0 * (w * y - z * x))
        yaw = libm_each(math.atan2, 2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.stack([roll, pitch, yaw], axis=1)


def angular_velocities(r0: np.ndarray, r1: np.ndarray, dt_s: float, native: bool = True) -> np.ndarray:
    """motion_sensors.angular_velocity of each pair of (k, 3, 3) world rotations: (k, 3) rad/s in
    the frame of ``r1``."""
    rel = np.matmul(np.ascontiguousarray(r0).transpose(0, 2, 1), r1)     # r0.T @ r1, item by item
    got = packets.gyro_rates(rel, dt_s) if native else None
    if got is not None:
        return got
    trace = rel[:, 0, 0] + rel[:, 1, 1] + rel[:, 2, 2]                   # np.trace: summed left to right
    angle = libm_each(lambda t: math.acos(max(-1.0, min(1.0, (t - 1.0) / 2.0))), trace)
    v = np.stack([rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]], axis=1)
    small = angle < 1e-6                                                  # sin(angle) ~ angle: the skew part
    with np.errstate(invalid="ignore", divide="ignore"):
        turned = v * (angle / (2.0 * libm_each(math.sin, angle)))[:, None] / dt_s
    return np.where(small[:, None], v / 2.0 / dt_s, turned)


def _axes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A convex hull's (counter-clockwise points, as contact keeps them) edges' outward unit normals
    (k, 2) and its support along each, ``max(points @ normal)`` (k,); none for a single point (a
    hull of two points: the segment's two normals)."""
    if len(points) < 2:
        return np.zeros((0, 2)), np.zeros(0)
    d = np.roll(points, -1, axis=0) - points
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 0.0
    normals = np.stack([d[keep, 1], -d[keep, 0]], axis=1) / length[keep, None]
    return normals, np.max(points @ normals.T, axis=0)


def _placed(hull: tuple, cx: np.ndarray, cy: np.ndarray, c: np.ndarray, s: np.ndarray) -> tuple:
    """A hull (its points' x, y, :func:`_axes`' normals and supports, in its own frame) turned by
    (cos, sin) = (``c``, ``s``) and moved to (``cx``, ``cy``), one row per copy: points' x, y
    (n, V), normals' x, y and supports (n, F)."""
    vx, vy, normals, support = hull
    c, s, cx, cy = c[:, None], s[:, None], cx[:, None], cy[:, None]
    mx = c * normals[None, :, 0] - s * normals[None, :, 1]
    my = s * normals[None, :, 0] + c * normals[None, :, 1]
    return (cx + (c * vx[None, :] - s * vy[None, :]), cy + (s * vx[None, :] + c * vy[None, :]),
            mx, my, mx * cx + my * cy + support[None, :])


def _hull_gap(a: tuple, b: tuple) -> np.ndarray:
    """A lower bound of the distance between two convex hulls placed per copy (:func:`_placed`, or
    with one row for all copies): the widest gap between their projections on an edge normal of
    either (0 or less where they overlap on every one; -inf with no normals)."""
    gap = -math.inf
    for (x, y, _, _, _), (_, _, mx, my, sup) in ((a, b), (b, a)):
        if mx.shape[1] and x.shape[1]:
            proj = x[:, :, None] * mx[:, None, :] + y[:, :, None] * my[:, None, :]
            gap = np.maximum(gap, np.max(np.min(proj, axis=1) - sup, axis=1))
    return np.asarray(gap)


class KinematicDevices:
    """The GPS, Compass, InertialUnit, Gyro, Accelerometer, TouchSensor and Altimeter devices of a
    batched simulation: their
    constants stacked per kind, their state beyond ``values`` (a GPS's speed, speed vector, noise
    state and previous position; an inertial unit's quaternion; the poses a gyro or an
    accelerometer differences) per copy, and :meth:`measure` for one step.

    ``sim`` is the BatchedSimulation (its poses, clocks, schedules, values, noise bank);
    ``devices`` its template devices of each kind, in column order."""

    def __init__(self, sim: Any, devices: dict[str, list]):
        self.sim = sim
        self.devices = {k: devices.get(k, []) for k in KINDS}
        C = sim.copies
        wi = sim.world.world_info
        self.axes = wi.coordinate_system
        self.reference, self.utm = gps_reference(wi)
        self.north = orient.north_vector(self.axes)
        self.slot = {k: np.array([d.robot_index for d in v], dtype=np.int64) for k, v in self.devices.items()}
        self.local_rot = {k: np.array([d.local_pose.rotation for d in v]).reshape(-1, 3, 3)
                          for k, v in self.devices.items()}
        self.local_pos = {k: np.array([d.local_pose.translation for d in v]).reshape(-1, 3)
                          for k, v in self.devices.items()}
        self.resolution = {k: np.array([float(d.config.resolution) for d in v]) for k, v in self.devices.items()}
        gps = [d.config for d in self.devices["GPS"]]
        self.accuracy = np.array([c.accuracy for c in gps], dtype=np.float64)
        self.correlation = np.array([c.noise_correlation for c in gps], dtype=np.float64)
        self.speed_noise = np.array([c.speed_noise for c in gps], dtype=np.float64)
        self.speed_resolution = np.array([c.speed_resolution for c in gps], dtype=np.float64)
        n = len(gps)
        self.speed = np.full((C, n), math.nan)
        self.speed_vector = np.full((C, n, 3), math.nan)
        self.gps_noise = np.zeros((C, n, 3))                 # each GPS's Gauss-Markov state
        self.previous = np.zeros((C, n, 3))                  # the translation at its previous measurement
        self.has_previous = np.zeros((C, n), dtype=bool)
        units = [d.config for d in self.devices["InertialUnit"]]
        self.unit_noise = np.array([c.noise for c in units], dtype=np.float64)
        self.unit_axes = [np.array([getattr(c, a) for c in units], dtype=bool) for a in ("x_axis", "y_axis", "z_axis")]
        self.quaternion = np.full((C, len(units), 4), math.nan)
        # Altimeter: the height along up (ENU: z, NUE: y) plus the reference altitude (Altimeter's)
        self.altitude_offset = altitude_offset(wi)
        self.altimeter_accuracy = np.array([d.config.accuracy for d in self.devices["Altimeter"]], dtype=np.float64)
        # the kinds read through a lookup table per enabled axis (axes_through_table): each device's axes on
        self.axes_on = {k: [np.array([d.config.x_axis, d.config.y_axis, d.config.z_axis], dtype=bool).nonzero()[0]
                            for d in self.devices[k]] for k in ("Compass", *MOTION)}
        # Gyro and Accelerometer: every slot's end-of-step poses of the copy's last two steps, and per
        # device the robot's pose when it was enabled and how many poses it has seen (_MotionSensor._poses)
        self.dt_s = sim.basic_time_step / 1000.0
        self.gravity_up = float(wi.gravity) * motion_math.up_vector(self.axes)
        self.tracking = any(self.devices[k] for k in MOTION)
        R = sim.R
        self.last_rot = np.zeros((C, R, 3, 3))
        self.last_pos = np.zeros((C, R, 3))
        self.last2_rot = np.zeros((C, R, 3, 3))
        self.last2_pos = np.zeros((C, R, 3))
        self.seen = {k: np.zeros((C, len(self.devices[k])), dtype=np.int64) for k in MOTION}
        # bumpers with bounding shapes of their own: those shapes (primitive, pose in the robot frame),
        # made into contact's pieces when first due (TouchSensor.bind and measure)
        self.bumper_own: list[list] = []
        for d in self.devices["TouchSensor"]:
            robot = sim.world.robots[d.robot_index]
            self.bumper_own.append([(primitive_from_model(p.geometry, sim.loaded.base_dir), pose_from_model(p.pose))
                                    for p in robot.shapes
                                    if p.of_device == d.name and p.seen_by in ("both", "bounding")])
        self.bumper_pieces: dict[int, list] = {}
        self.bumper_discs: dict[int, np.ndarray] = {}    # per piece its disc (_bumper_shapes)
        self.bumper_hulls: dict[int, list] = {}          # per piece its points and axes (_bumper_shapes)
        self._solid_cache: dict[int, tuple] = {}         # a solid's hull (_solid_hull)
        self.robot_hulls: dict[int, tuple] = {}          # a shaped robot's footprint hull, own frame
        # bumpers between readings (TouchSensor.sample): the touch since the last reading, whether
        # enabled since the copy was built or reset, and whether any may be asked between readings
        nb = len(self.devices["TouchSensor"])
        self.touched = np.zeros((C, nb), dtype=bool)
        self.armed = np.zeros((C, nb), dtype=bool)
        self.latching = False
        self.enable_rot = {k: np.zeros((C, len(self.devices[k]), 3, 3)) for k in MOTION}
        self.enable_pos = {k: np.zeros((C, len(self.devices[k]), 3)) for k in MOTION}
        # a gyro or an accelerometer riding a joint: its local pose moves too, so per copy its local
        # poses at enable and at the last two steps' ends are kept beside the robot's (batched_joints.py)
        joints = sim.joints
        self.motion_riders: dict[tuple[str, int], dict[str, tuple[np.ndarray, np.ndarray]]] = {
            key: {when: (joints.local_rot[key].copy(), joints.local_pos[key].copy()) for when in ("enable", "last", "last2")}
            for key in joints.riders if key[0] in MOTION}

    # ------------------------------------------------------------------ state
    def reset(self, idx: np.ndarray) -> None:
        """The named copies' state as a freshly built world's (``values`` are the simulation's)."""
        self.speed[idx] = math.nan
        self.speed_vector[idx] = math.nan
        self.gps_noise[idx] = 0.0
        self.previous[idx] = 0.0
        self.has_previous[idx] = False
        self.quaternion[idx] = math.nan
        for k in MOTION:
            self.seen[k][idx] = 0
        self.touched[idx] = False
        self.armed[idx] = False

    def enabled(self, kind: str, column: int, idx) -> None:
        """``enable`` of a device in the copies ``idx``: a gyro or an accelerometer starts its poses
        over from the robot's pose now (_MotionSensor.enable); a bumper enabled is armed (and one
        due less often than every step, or disabled once armed, is asked between readings)."""
        if kind == "TouchSensor":
            per = self.sim.period[kind][idx, column]
            if ((per > self.sim.basic_time_step) | ((per == 0) & self.armed[idx, column])).any():
                self.latching = True
            self.armed[idx, column] |= per > 0
        if kind in MOTION:
            slot = self.slot[kind][column]
            self.seen[kind][idx, column] = 1
            kept = self.motion_riders.get((kind, column))
            if kept is not None:
                joints = self.sim.joints
                kept["enable"][0][idx] = joints.local_rot[(kind, column)][idx]
                kept["enable"][1][idx] = joints.local_pos[(kind, column)][idx]
            self.enable_rot[kind][idx, column] = self.sim.rot[idx, slot]
            self.enable_pos[kind][idx, column] = self.sim.pos[idx, slot]

    def placed(self, copy: int, slot: int) -> None:
        """A robot of one copy was put somewhere from outside (``set_pose``): its gyros and
        accelerometers start their poses over from there (_MotionSensor.placed)."""
        for kind in MOTION:
            for column in np.nonzero(self.slot[kind] == slot)[0].tolist():
                self.enabled(kind, column, np.array([copy]))

    def reading(self, kind: str, column: int, what: str) -> np.ndarray:
        """A device's reading ``what`` (one of READINGS[kind]) in every copy: (copies, ...)."""
        if what not in READINGS.get(kind, ()):
            raise AttributeError(f"a {kind} has no reading {what!r} (readings: {', '.join(READINGS.get(kind, ()))})")
        if what in ("values", "roll_pitch_yaw", "value"):
            return self.sim.values[kind][:, column]
        return {"speed": self.speed, "speed_vector": self.speed_vector, "quaternion": self.quaternion}[what][:, column]

    # ------------------------------------------------------------------ measuring
    def measure(self, live: np.ndarray) -> None:
        """Every due device of these kinds in the copies ``live``, at their end-of-step poses; then
        the poses gyros and accelerometers keep (every step, as the single simulation's ``track``)."""
        if self.latching:
            self._sample_bumpers(live)
        for kind, fn in (("GPS", self._gps), ("Compass", self._compass), ("InertialUnit", self._unit),
                         ("Gyro", self._gyro), ("Accelerometer", self._accelerometer), ("TouchSensor", self._bumper_read),
                         ("Altimeter", self._altimeter)):
            if self.devices[kind]:
                copies, cols = self.sim._due(kind, live)
                if len(copies):
                    self.sim._store(kind, copies, cols, fn(copies, cols))
        if self.tracking:
            self._track(live)

    def _track(self, live: np.ndarray) -> None:
        """The step's end poses join the kept ones (a pose list is at most 3 long)."""
        sim = self.sim
        for k in MOTION:
            if self.devices[k]:
                self.seen[k][live] = np.minimum(self.seen[k][live] + 1, 3)
        self.last2_rot[live] = self.last_rot[live]
        self.last2_pos[live] = self.last_pos[live]
        self.last_pos[live] = sim.pos[live]
        self.last_rot[live] = sim.rot[live]
        for key, kept in self.motion_riders.items():
            for k in (0, 1):
                kept["last2"][k][live] = kept["last"][k][live]
            kept["last"][0][live] = sim.joints.local_rot[key][live]
            kept["last"][1][live] = sim.joints.local_pos[key][live]

    def _poses(self, kind: str, copies: np.ndarray, cols: np.ndarray):
        """The device poses of a due gyro or accelerometer as its pose list holds them after this
        step's: (n, (rotation, translation) of the robot at each of the last three poses, newest last),
        ``n`` the list's length (2 or 3) and each robot pose chosen among this step's, the kept ones
        and the pose when it was enabled."""
        sim = self.sim
        slot = self.slot[kind][cols]
        before = self.seen[kind][copies, cols]
        n = np.minimum(before + 1, 3)
        now_rot, now_pos = sim.rot[copies, slot], sim.pos[copies, slot]
        e_rot, e_pos = self.enable_rot[kind][copies, cols], self.enable_pos[kind][copies, cols]
        # poses[-2]: the enable pose after one step, else the previous step's end (this one's before any)
        one, two = (n == 2), (n >= 3)
        prev_rot = np.where(two[:, None, None], self.last_rot[copies, slot], np.where(one[:, None, None], e_rot, now_rot))
        prev_pos = np.where(two[:, None], self.last_pos[copies, slot], np.where(one[:, None], e_pos, now_pos))
        # poses[-3] (three known): the enable pose two steps after it, else the end of the step before last
        older = before >= 3
        first_rot = np.where(older[:, None, None], self.last2_rot[copies, slot], e_rot)
        first_pos = np.where(older[:, None], self.last2_pos[copies, slot], e_pos)
        return n, (now_rot, now_pos), (prev_rot, prev_pos), (first_rot, first_pos)

    def _motion_locals(self, kind: str, copies: np.ndarray, cols: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """The device's local poses at the three poses :meth:`_poses` picks (now, previous, first),
        chosen the same way: the file's for a device on the body, each copy's kept ones for a device
        riding a joint (whose local pose moved with it)."""
        fixed = (self.local_rot[kind][cols], self.local_pos[kind][cols])
        out = [(fixed[0].copy(), fixed[1].copy()) for _ in range(3)]
        riding = [col for col in unique_ints(cols).tolist() if (kind, col) in self.motion_riders]
        if not riding:
            return out
        before = self.seen[kind][copies, cols]
        n = np.minimum(before + 1, 3)
        joints = self.sim.joints
        for col in riding:
            m = (cols == col).nonzero()[0]
            c = copies[m]
            kept = self.motion_riders[(kind, col)]
            now = (joints.local_rot[(kind, col)][c], joints.local_pos[(kind, col)][c])
            one, two, older = (n[m] == 2), (n[m] >= 3), (before[m] >= 3)
            e, last, last2 = [(kept[w][0][c], kept[w][1][c]) for w in ("enable", "last", "last2")]
            prev = (np.where(two[:, None, None], last[0], np.where(one[:, None, None], e[0], now[0])),
                    np.where(two[:, None], last[1], np.where(one[:, None], e[1], now[1])))
            first = (np.where(older[:, None, None], last2[0], e[0]), np.where(older[:, None], last2[1], e[1]))
            for i, (r, p) in enumerate((now, prev, first)):
                out[i][0][m] = r
                out[i][1][m] = p
        return out

    @staticmethod
    def _compose(local: tuple[np.ndarray, np.ndarray], rot: np.ndarray, pos: np.ndarray | None):
        """Device.world_pose from robot poses and the device's local poses ``local`` (rotation R·Rl,
        translation R·tl + t; None: no translation)."""
        rr = np.ascontiguousarray(rot)
        r = np.matmul(rr, local[0])
        if pos is None:
            return r, None
        return r, np.matmul(rr, local[1][:, :, None])[:, :, 0] + pos

    def _frames(self, kind: str, copies: np.ndarray, cols: np.ndarray, translation: bool = True):
        """Device.world_pose of each due device: robot pose ∘ local pose, as Pose.compose computes it
        (rotation R·Rl, translation R·tl + t), stacked; a device riding a joint at its copy's local
        pose (batched_joints.py)."""
        slot = self.slot[kind][cols]
        rr = np.ascontiguousarray(self.sim.rot[copies, slot])       # contiguous 3x3s, as a Pose holds them
        local_rot, local_pos = self.local_rot[kind][cols], self.local_pos[kind][cols]
        joints = self.sim.joints
        riding = [col for col in unique_ints(cols).tolist() if (kind, col) in joints.riders] if joints.riders else []
        if riding:
            local_rot, local_pos = local_rot.copy(), local_pos.copy()
            for col in riding:
                m = (cols == col).nonzero()[0]
                local_rot[m] = joints.local_rot[(kind, col)][copies[m]]
                local_pos[m] = joints.local_pos[(kind, col)][copies[m]]
        rot = np.matmul(rr, local_rot)
        if not translation:
            return rot, None
        return rot, np.matmul(rr, local_pos[:, :, None])[:, :, 0] + self.sim.pos[copies, slot]

    def _gauss(self, kind: str, copies: np.ndarray, cols: np.ndarray, count: int) -> np.ndarray:
        """(k, count) standard normals: ``count`` in order from each (copy, device) stream."""
        streams = self.sim._noise_of[kind][cols]
        return np.stack([self.sim.noise.next(copies, streams) for _ in range(count)], axis=1)

    def _gps(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """GPS.measure (devices/gps.py position, speed_vector, speed) in local coordinates."""
        sim = self.sim
        _, t = self._frames("GPS", copies, cols)
        assert t is not None
        elapsed = sim.time_ms[copies] - sim.last["GPS"][copies, cols]
        p = t + self.reference
        acc = self.accuracy[cols]
        rows = (acc != 0.0).nonzero()[0]
        if len(rows):                    # the Gauss-Markov noise: three normals per measurement
            c, d = copies[rows], cols[rows]
            corr = self.correlation[d]
            ratio = correlation_ratios(corr, elapsed[rows] / 1000.0)
            state = self.gps_noise[c, d] * ratio[:, None]
            state = state + np.sqrt(1.0 - ratio * ratio)[:, None] * self._gauss("GPS", c, d, 3)
            self.gps_noise[c, d] = state
            p[rows] = p[rows] + acc[rows, None] * state
        p = _quantize(p, self.resolution["GPS"][cols])
        if self.utm is not None:
            p = wgs84_positions(self.utm, p, self.axes)
        known = self.has_previous[copies, cols] & (elapsed > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            vec = np.where(known[:, None], (t - self.previous[copies, cols]) * (1000.0 / elapsed)[:, None], math.nan)
        self.previous[copies, cols] = t
        self.has_previous[copies, cols] = True
        self.speed_vector[copies, cols] = vec
        speed = np.sqrt(_dots(vec))
        sn = self.speed_noise[cols]
        rows = (sn > 0.0).nonzero()[0]
        if len(rows):                    # one more normal, after the position's
            g = self._gauss("GPS", copies[rows], cols[rows], 1)[:, 0]
            speed[rows] = speed[rows] * (1.0 + sn[rows] * g)
        self.speed[copies, cols] = _quantize(speed, self.speed_resolution[cols])
        return p

    def _compass(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Compass.measure (orientation.compass_values): north in the device frame through each
        compass's lookup table, its noise, its resolution; NaN on a disabled axis."""
        rot, _ = self._frames("Compass", copies, cols, translation=False)
        local = np.matmul(rot.transpose(0, 2, 1), self.north[:, None])[:, :, 0]     # Rᵀ·north
        local = local / np.sqrt(_dots(local))[:, None]
        return self._through_tables("Compass", copies, cols, local)

    def _through_tables(self, kind: str, copies: np.ndarray, cols: np.ndarray, raw: np.ndarray) -> np.ndarray:
        """motion_sensors.axes_through_table of each row: each enabled axis through the device's
        lookup table (its noise from its own stream, in axis order), then its resolution; NaN on a
        disabled axis."""
        out = np.full((len(copies), 3), math.nan)
        streams = self.sim._noise_of[kind]
        for col in unique_ints(cols).tolist():
            sel = (cols == col).nonzero()[0]
            on = self.axes_on[kind][col]
            if not len(on):
                continue
            v = raw[sel][:, on]
            table = self.devices[kind][col].table
            if len(table):               # LookupTable.lookup: interpolated, then y (1 + n G) per noisy entry
                v, nz = table.interpolate(v)
                for j in range(len(on)):  # the entries in C order: each row's axes in turn
                    noisy = (nz[:, j] != 0.0).nonzero()[0]
                    if len(noisy):
                        g = self.sim.noise.next(copies[sel][noisy], np.full(len(noisy), streams[col]))
                        v[noisy, j] = v[noisy, j] * (1.0 + nz[noisy, j] * g)
            res = self.resolution[kind][col]
            if res != RESOLUTION_OFF:
                v = np.trunc(v / res + 0.5) * res + 0.0
            out[np.ix_(sel, on)] = v
        return out

    def _gyro(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Gyro.measure: the turn from the device's previous pose to this step's over one basic step."""
        n, (now_rot, _), (prev_rot, _), _ = self._poses("Gyro", copies, cols)
        now, prev, _ = self._motion_locals("Gyro", copies, cols)
        r1, _ = self._compose(now, now_rot, None)
        r0, _ = self._compose(prev, prev_rot, None)
        return self._through_tables("Gyro", copies, cols, angular_velocities(r0, r1, self.dt_s))

    def _accelerometer(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Accelerometer.measure: the second difference of the device's last three positions (rest
        until three are known) plus gravity, in the device frame (specific_force)."""
        n, (now_rot, now_pos), (prev_rot, prev_pos), (first_rot, first_pos) = self._poses("Accelerometer", copies, cols)
        now, prev, first = self._motion_locals("Accelerometer", copies, cols)
        rot, p2 = self._compose(now, now_rot, now_pos)
        _, p1 = self._compose(prev, prev_rot, prev_pos)
        _, p0 = self._compose(first, first_rot, first_pos)
        assert p0 is not None and p1 is not None and p2 is not None
        rest = (n < 3)[:, None]                          # fewer than three poses: p0 = p1 = p2
        p0, p1 = np.where(rest, p2, p0), np.where(rest, p2, p1)
        dt = self.dt_s
        a = (p2 - 2.0 * p1 + p0) / (dt * dt)
        force = np.matmul(rot.transpose(0, 2, 1), (a + self.gravity_up)[:, :, None])[:, :, 0]
        return self._through_tables("Accelerometer", copies, cols, force)

    def _unit(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """InertialUnit.measure: the quaternion (orientation.inertial_quaternion) and roll, pitch, yaw."""
        rot, _ = self._frames("InertialUnit", copies, cols, translation=False)
        noise = self.unit_noise[cols]
        noisy = (noise != 0.0).nonzero()[0]
        gauss = None
        if len(noisy):
            gauss = np.zeros((len(cols), 3))
            gauss[noisy] = self._gauss("InertialUnit", copies[noisy], cols[noisy], 3)
        x, y, z = (a[cols] for a in self.unit_axes)
        q = inertial_quaternions(matrix_quaternions(rot), gauss, noise, x, y, z, self.resolution["InertialUnit"][cols])
        self.quaternion[copies, cols] = q
        return roll_pitch_yaw(q, self.axes)

    def _sample_bumpers(self, live: np.ndarray) -> None:
        """TouchSensor.sample in the copies ``live``: every armed bumper that is not due and has not
        touched since its last reading is asked whether it touches now (:meth:`_bumper`, all of
        them at once), its flag set where it does."""
        sim = self.sim
        per = sim.period["TouchSensor"][live]
        due = (per > 0) & (sim.time_ms[live][:, None] - sim.last["TouchSensor"][live] >= per)
        ci, cols = (self.armed[live] & ~self.touched[live] & ~due).nonzero()
        if len(ci):
            copies = live[ci]
            self.touched[copies, cols] = self._bumper(copies, cols) != 0.0

    def _bumper_read(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """A due bumper's reading (TouchSensor.measure): 1 where it touched since its last reading
        or touches now, its flag cleared."""
        out = self._bumper(copies, cols)
        if self.latching:
            out = np.where(self.touched[copies, cols], 1.0, out)
            self.touched[copies, cols] = False
        return out

    def _bumper(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """TouchSensor.measure of a bumper: one without shapes of its own reads 1 where the copy's
        robot pushed against something in this step (kinematic contact clipped its move:
        ``pressing``); one with shapes reads 1 where they touch a solid or another robot of its copy
        at the end of the step (contact.pieces_touch, from the copy's contact state as the single
        simulation's Contact keeps it), else 0. Shaped bumpers go through a broad phase on every
        due copy at once (:meth:`_bumper_near`), and pieces_touch runs only on the pieces and
        obstacles it leaves: the others are farther apart than pieces_touch could find touching, so
        the answer is that of pieces_touch on them all."""
        sim = self.sim
        slots = self.slot["TouchSensor"][cols]
        out = np.where(sim.pressing[copies, slots], 1.0, 0.0)
        has = np.fromiter((bool(self.bumper_own[col]) for col in cols.tolist()), dtype=bool, count=len(cols))
        if not has.any():
            return out
        if sim.contact is None:
            out[has] = 0.0
            return out
        for col in unique_ints(cols[has]).tolist():
            rows = (cols == col).nonzero()[0]
            out[rows] = self._bumper_near(copies[rows], int(col))
        return out

    def _bumper_shapes(self, col: int) -> tuple[list, np.ndarray, list]:
        """Bumper ``col``'s pieces (contact.device_pieces, made when first due), per piece a disc in
        the footprint's frame holding it with its rounding: (centre x, centre y, radius, z_low,
        z_high) rows, and per piece its points' x and y, its edges' outward unit normals and its
        support along each (:func:`_axes`), as :func:`_placed` takes them."""
        sim = self.sim
        pieces = self.bumper_pieces.get(col)
        if pieces is None:
            r = int(self.slot["TouchSensor"][col])
            tpl = sim._templates[r]
            pieces = self.bumper_pieces[col] = device_pieces(self.bumper_own[col], sim.initial[r], sim.to_enu,
                                                             None if tpl is None else tpl.yaw)
            discs, hulls = [], []
            for piece in pieces:
                centre = (piece.points.min(axis=0) + piece.points.max(axis=0)) / 2.0
                radius = float(np.max(np.hypot(*(piece.points - centre).T))) + piece.round
                discs.append((float(centre[0]), float(centre[1]), radius, piece.z_low, piece.z_high))
                hulls.append((piece.points[:, 0].copy(), piece.points[:, 1].copy(), *_axes(piece.points)))
            self.bumper_discs[col] = np.array(discs, dtype=np.float64).reshape(-1, 5)
            self.bumper_hulls[col] = hulls
        return pieces, self.bumper_discs[col], self.bumper_hulls[col]

    def _solid_hull(self, ob: Obstacle) -> tuple:
        """A solid's hull as :func:`_placed` gives it (one row), kept while the solid's obstacle is
        the same object (moving a solid makes a new one)."""
        got = self._solid_cache.get(id(ob))
        if got is None or got[0] is not ob:
            one, zero = np.ones(1), np.zeros(1)
            hull = (ob.points[:, 0].copy(), ob.points[:, 1].copy(), *_axes(ob.points))
            got = self._solid_cache[id(ob)] = (ob, _placed(hull, zero, zero, one, zero))
        return got[1]

    def _bumper_near(self, copies: np.ndarray, col: int) -> np.ndarray:
        """Shaped bumper ``col`` in ``copies``: 1.0 where contact.pieces_touch says its pieces touch.
        The broad phase, on all copies at once: each piece (turned and moved with its robot) against
        every solid and every other robot of its copy, with pieces_touch's height-band test and a
        lower bound of their distance -- the piece's disc against the solid's box, a wall line or
        the robot's disc, and for a solid the widest gap along an edge normal of either hull --
        more than TOUCH plus a slack far above the rounding of the two ways of computing it; any
        such pair is apart in pieces_touch too, which runs only on the pairs left."""
        sim = self.sim
        r = int(self.slot["TouchSensor"][col])
        pieces, discs, hulls = self._bumper_shapes(col)
        out = np.zeros(len(copies))
        if not pieces:
            return out
        centres = sim.centres[copies, r]                      # (n, 2)
        cx, cy = centres[:, 0:1], centres[:, 1:2]
        yaw = sim.foot_yaw[copies, r]
        height = sim.heights[copies, r]
        c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
        px = cx + (c * discs[None, :, 0] - s * discs[None, :, 1])    # (n, P): each piece's disc centre
        py = cy + (s * discs[None, :, 0] + c * discs[None, :, 1])
        reach = discs[None, :, 2] + (TOUCH + _SLACK)
        lo, hi = height[:, None] + discs[None, :, 3], height[:, None] + discs[None, :, 4]      # (n, P)
        solids = sim.contact._obs
        near_solid = np.zeros((len(copies), len(pieces), len(solids)), dtype=bool)
        for k, ob in enumerate(solids):
            band = (ob.z_range[1] > lo + FLOOR) & (ob.z_range[0] < hi - EPS)
            if not band.any():
                continue
            if ob.normal is not None:     # a wall line: the piece's disc wholly on its robot's side
                n0, n1 = float(ob.normal[0]), float(ob.normal[1])
                at = n0 * centres[:, 0] + n1 * centres[:, 1] + ob.offset
                side = np.where(at >= 0.0, 1.0, -1.0)[:, None]        # (a centre on the line: kept)
                far = (side * (n0 * px + n1 * py + ob.offset) - reach > _SLACK * (1.0 + abs(ob.offset))) \
                    & (np.abs(at) > _SLACK)[:, None]
                near_solid[:, :, k] = band & ~far
                continue
            (lx, ly), (hx, hy) = ob.lo.tolist(), ob.hi.tolist()
            far = (px - reach > hx) | (px + reach < lx) | (py - reach > hy) | (py + reach < ly)
            near = band & ~far
            hull = self._solid_hull(ob)
            for q in range(len(pieces)):
                rows = near[:, q].nonzero()[0]
                if len(rows):
                    gap = _hull_gap(_placed(hulls[q], cx[rows, 0], cy[rows, 0], c[rows, 0], s[rows, 0]), hull)
                    near[rows, q] = gap - (ob.radius + pieces[q].round) <= TOUCH + _SLACK
            near_solid[:, :, k] = near
        others = [j for j, foot in enumerate(sim.feet) if foot is not None and j != r]
        near_robot = np.zeros((len(copies), len(pieces), len(others)), dtype=bool)
        for k, j in enumerate(others):
            foot = sim.feet[j]
            jc = sim.centres[copies, j]
            jh = sim.heights[copies, j]
            band = ((jh + sim.foot_high[j])[:, None] > lo + EPS) & ((jh + sim.foot_low[j])[:, None] < hi - EPS)
            dist = np.hypot(px - jc[:, 0:1], py - jc[:, 1:2])
            near = band & (dist <= reach + (foot.radius + _SLACK))
            if sim._shaped[j]:            # its footprint's hull where it is in each copy
                assert foot.points is not None
                hull_j = self.robot_hulls.get(j)
                if hull_j is None:
                    hull_j = self.robot_hulls[j] = (foot.points[:, 0].copy(), foot.points[:, 1].copy(),
                                                    *_axes(foot.points))
                for q in range(len(pieces)):
                    rows = near[:, q].nonzero()[0]
                    if len(rows):
                        yj = sim.foot_yaw[copies[rows], j]
                        other = _placed(hull_j, jc[rows, 0], jc[rows, 1], np.cos(yj), np.sin(yj))
                        gap = _hull_gap(_placed(hulls[q], cx[rows, 0], cy[rows, 0], c[rows, 0], s[rows, 0]), other)
                        near[rows, q] = gap - (foot.round + pieces[q].round) <= TOUCH + _SLACK
            near_robot[:, :, k] = near
        rows = (near_solid.any(axis=(1, 2)) | near_robot.any(axis=(1, 2))).nonzero()[0]
        for m in rows.tolist():
            cc = int(copies[m])
            for q, piece in enumerate(pieces):
                obs = [solids[k] for k in near_solid[m, q].nonzero()[0].tolist()]
                robots = [ob for k in near_robot[m, q].nonzero()[0].tolist() for ob in self._robot_obstacles(cc, others[k])]
                if (obs or robots) and pieces_touch([piece], sim.centres[cc, r], float(sim.foot_yaw[cc, r]),
                                                    float(sim.heights[cc, r]), obs, robots):
                    out[m] = 1.0
                    break
        return out

    def _robot_obstacles(self, c: int, j: int) -> list[Obstacle]:
        """Robot ``j`` of copy ``c`` where it is now, as obstacles (Contact._robot_obstacles)."""
        sim = self.sim
        band = (float(sim.heights[c, j] + sim.foot_low[j]), float(sim.heights[c, j] + sim.foot_high[j]))
        return robot_obstacles(j, sim.feet[j], sim.centres[c, j], float(sim.foot_yaw[c, j]), band)

    def _altimeter(self, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Altimeter.measure: the device's height (+ the reference altitude), its Gaussian
        accuracy noise (one normal from its stream), its resolution."""
        _, t = self._frames("Altimeter", copies, cols)
        assert t is not None
        v = t[:, self.axes.index("U")] + self.altitude_offset
        acc = self.altimeter_accuracy[cols]
        rows = (acc > 0.0).nonzero()[0]
        if len(rows):
            v[rows] = v[rows] + acc[rows] * self._gauss("Altimeter", copies[rows], cols[rows], 1)[:, 0]
        return _quantize(v, self.resolution["Altimeter"][cols])
