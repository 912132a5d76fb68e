"""Topic payloads (PROTOCOL.md §4): ROS 2 message shapes as pydantic models.

Field names and order are those of ``sensor_msgs``/``std_msgs``/``builtin_interfaces``/
``rosgraph_msgs``/``geometry_msgs`` (wire.md §1; BatteryState adds one of its own last, ``energy``); arrays
travel as little-endian raw bytes (``bytes`` fields, dtype named in each field's description). The server builds plain dicts in this order on its hot path;
these models are the contract (JSON Schema export, tests, clients that want validation).
"""

from __future__ import annotations

import math
from typing import ClassVar

from pydantic import BaseModel, ConfigDict, Field


class Msg(BaseModel):
    """Base: unknown fields are errors; NaN/±inf are valid values (REP-117 special ranges)."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


class Time(Msg):
    """``builtin_interfaces/msg/Time``."""

    sec: int = Field(ge=-(1 << 31), lt=1 << 31)
    nanosec: int = Field(ge=0, lt=1_000_000_000)


class Header(Msg):
    """``std_msgs/msg/Header``: stamp = simulated time of the measurement; frame_id = ``robot/device``
    (``world`` for a robot's pose)."""

    stamp: Time
    frame_id: str


class Illuminance(Msg):
    """``sensor_msgs/msg/Illuminance`` for a LightSensor: the lookup-table output, variance 0."""

    header: Header
    illuminance: float
    variance: float = 0.0


class Range(Msg):
    """``sensor_msgs/msg/Range`` (Iron and later, with ``variance``) for a DistanceSensor."""

    ULTRASOUND: ClassVar[int] = 0
    INFRARED: ClassVar[int] = 1

    header: Header
    radiation_type: int = Field(ge=0, le=255, description="0 sonar (and generic, laser), 1 infra-red")
    field_of_view: float = Field(description="rad: the sensor's aperture")
    min_range: float = Field(description="minimum of the lookup table's output column")
    max_range: float = Field(description="maximum of the lookup table's output column")
    range: float = Field(description="the lookup-table output (the controller's value)")
    variance: float = 0.0


class Image(Msg):
    """``sensor_msgs/msg/Image``: a lidar or range-finder range image is ``32FC1`` (a lidar: one row
    per layer), a camera image ``bgra8`` (Webots' byte order), its segmentation image too."""

    header: Header
    height: int = Field(ge=0, lt=1 << 32)
    width: int = Field(ge=0, lt=1 << 32)
    encoding: str
    is_bigendian: int = Field(ge=0, le=1)
    step: int = Field(ge=0, lt=1 << 32, description="bytes per row")
    data: bytes = Field(description="height x step bytes; 32FC1 = little-endian float32")


class RegionOfInterest(Msg):
    """``sensor_msgs/msg/RegionOfInterest``."""

    x_offset: int = Field(default=0, ge=0, lt=1 << 32)
    y_offset: int = Field(default=0, ge=0, lt=1 << 32)
    height: int = Field(default=0, ge=0, lt=1 << 32)
    width: int = Field(default=0, ge=0, lt=1 << 32)
    do_rectify: bool = False


class CameraInfo(Msg):
    """``sensor_msgs/msg/CameraInfo`` of a planar camera or range finder: the pinhole of its exact
    pixel rays (square pixels, pixel centres at integer coordinates), no distortion. ``header`` is
    the image's (frame ``robot/device``: FLU, x along the optical axis, as Webots)."""

    header: Header
    height: int = Field(ge=0, lt=1 << 32)
    width: int = Field(ge=0, lt=1 << 32)
    distortion_model: str = "plumb_bob"
    d: bytes = Field(description="little-endian float64[5]: zeros")
    k: bytes = Field(description="little-endian float64[9]: fx 0 cx / 0 fy cy / 0 0 1 (row-major)")
    r: bytes = Field(description="little-endian float64[9]: identity")
    p: bytes = Field(description="little-endian float64[12]: fx 0 cx 0 / 0 fy cy 0 / 0 0 1 0")
    binning_x: int = Field(default=0, ge=0, lt=1 << 32)
    binning_y: int = Field(default=0, ge=0, lt=1 << 32)
    roi: RegionOfInterest = RegionOfInterest()


class LaserScan(Msg):
    """``sensor_msgs/msg/LaserScan`` for a one-layer cylindrical lidar, ranges left to right."""

    header: Header
    angle_min: float = Field(description="rad: azimuth of ranges[0] (the leftmost column)")
    angle_max: float = Field(description="rad: azimuth of the last range")
    angle_increment: float = Field(description="rad, negative: ranges go left to right")
    time_increment: float = Field(description="s between two measurements")
    scan_time: float = Field(description="s between scans")
    range_min: float
    range_max: float
    ranges: bytes = Field(description="little-endian float32[]")
    intensities: bytes = Field(default=b"", description="little-endian float32[]; empty")


class ChannelFloat32(Msg):
    """``sensor_msgs/msg/ChannelFloat32``."""

    name: str
    values: bytes = Field(description="little-endian float32[], one per point")


class PointCloud(Msg):
    """``sensor_msgs/msg/PointCloud``. Extension: ``points`` is one bin of N x 3 little-endian
    float32 (x, y, z) instead of a list of Point32 maps."""

    header: Header
    points: bytes = Field(description="little-endian float32[N][3]: x, y, z in the device frame (m)")
    channels: list[ChannelFloat32] = Field(description='[{"name": "layer", "values": layer index per point}]')


class Point(Msg):
    """``geometry_msgs/msg/Point`` (float64)."""

    x: float
    y: float
    z: float


class Quaternion(Msg):
    """``geometry_msgs/msg/Quaternion`` (float64, ROS order x, y, z, w)."""

    x: float
    y: float
    z: float
    w: float


class Pose(Msg):
    """``geometry_msgs/msg/Pose``."""

    position: Point
    orientation: Quaternion


class PoseStamped(Msg):
    """``geometry_msgs/msg/PoseStamped``: a robot's pose in the world frame (``frame_id`` ``world``),
    stamped with the simulated time after each basic step."""

    header: Header
    pose: Pose


class Clock(Msg):
    """``rosgraph_msgs/msg/Clock``: the simulated time after each basic step."""

    clock: Time


class JointState(Msg):
    """``sensor_msgs/msg/JointState``. A PositionSensor's ``value``: one joint, named after the
    sensor, its angle (rad) as the controller reads it, velocity and effort empty. A robot's
    ``/<robot>/joint_states``: its joint motors (those no drive owns, in device order), their
    positions and velocities (the change over the last basic step ÷ its length), effort empty."""

    header: Header
    name: list[str]
    position: bytes = Field(description="<f8[len(name)]: rad (m for a slider)")
    velocity: bytes = Field(default=b"", description="<f8[]: empty, or <f8[len(name)] rad/s (m/s) on joint_states")
    effort: bytes = Field(default=b"", description="<f8[]: empty")


class ColorRGBA(Msg):
    """``std_msgs/msg/ColorRGBA`` for an LED: the colour it shows (all 0 when off); a = 1 when on."""

    r: float
    g: float
    b: float
    a: float


class Vector3(Msg):
    """``geometry_msgs/msg/Vector3`` (float64)."""

    x: float
    y: float
    z: float


class PointStamped(Msg):
    """``geometry_msgs/msg/PointStamped``: a GPS position in local coordinates (m)."""

    header: Header
    point: Point


class Vector3Stamped(Msg):
    """``geometry_msgs/msg/Vector3Stamped``: a GPS speed vector (m/s, world axes)."""

    header: Header
    vector: Vector3


class NavSatStatus(Msg):
    """``sensor_msgs/msg/NavSatStatus``: status 0 = fix (STATUS_FIX), service 1 = GPS."""

    status: int = Field(ge=-128, le=127)
    service: int = Field(ge=0, le=65535)


class NavSatFix(Msg):
    """``sensor_msgs/msg/NavSatFix``: a GPS in a WGS84 world (degrees, m); the covariance is the
    diagonal of ``accuracy²`` (type 2, diagonal known), or unknown (type 0) without noise."""

    header: Header
    status: NavSatStatus
    latitude: float
    longitude: float
    altitude: float
    position_covariance: bytes = Field(description="<f8[9]: row-major, m²")
    position_covariance_type: int = Field(ge=0, le=3)


class Imu(Msg):
    """``sensor_msgs/msg/Imu`` for an InertialUnit: the orientation only; the angular velocity and
    linear acceleration covariances start with -1 (REP 145: not provided)."""

    header: Header
    orientation: Quaternion
    orientation_covariance: bytes = Field(description="<f8[9], row-major, rad²")
    angular_velocity: Vector3
    angular_velocity_covariance: bytes = Field(description="<f8[9]")
    linear_acceleration: Vector3
    linear_acceleration_covariance: bytes = Field(description="<f8[9]")


class MagneticField(Msg):
    """``sensor_msgs/msg/MagneticField`` for a Compass: its values (the lookup-table output of
    north in the device frame, not Tesla), covariance 0."""

    header: Header
    magnetic_field: Vector3
    magnetic_field_covariance: bytes = Field(description="<f8[9]")


class Float64(Msg):
    """``std_msgs/msg/Float64``: a GPS speed (m/s); its time is the envelope's ``stamp_ns``."""

    data: float


class String(Msg):
    """``std_msgs/msg/String``: a text a controller sent its robot window (``wwiSendText``); its time
    is the envelope's ``stamp_ns``."""

    data: str


class RadarReturn(Msg):
    """``radar_msgs/msg/RadarReturn`` (ROS 2's radar_msgs): one Radar target. ``azimuth`` follows
    REP 103 (positive to the left), so it is minus Webots' azimuth; ``amplitude`` is the received
    power in dBm; Webots measures no elevation (0)."""

    range: float = Field(description="m, the target's distance")
    azimuth: float = Field(description="rad, positive to the left (-Webots' azimuth)")
    elevation: float = Field(default=0.0, description="rad, always 0 (not measured)")
    doppler_velocity: float = Field(description="m/s, the radial speed (positive: moving away)")
    amplitude: float = Field(description="dBm, the received power")


class RadarScan(Msg):
    """``radar_msgs/msg/RadarScan`` for a Radar: its targets at one measurement."""

    header: Header
    returns: list[RadarReturn]


class BatteryState(Msg):
    """``sensor_msgs/msg/BatteryState`` of a robot's battery (Webots' ``battery`` field, in joules):
    ``percentage`` is the energy ÷ the maximum (NaN without a positive maximum); Webots models no
    voltage, current, charge in Ah, temperature or cells, so those are NaN (the ROS message's "not
    measured") or empty; ``power_supply_status`` says CHARGING while a Charger gives it energy, FULL
    at its maximum, DISCHARGING while it loses energy to ``cpuConsumption``, NOT_CHARGING otherwise. Last,
    ``energy`` (J), not ROS's: the battery sensor's value, which a battery without a maximum has too."""

    STATUS_CHARGING: ClassVar[int] = 1
    STATUS_DISCHARGING: ClassVar[int] = 2
    STATUS_NOT_CHARGING: ClassVar[int] = 3
    STATUS_FULL: ClassVar[int] = 4

    header: Header
    voltage: float = Field(description="V: NaN (Webots models no voltage)")
    temperature: float = Field(description="°C: NaN (not measured)")
    current: float = Field(description="A: NaN (not measured)")
    charge: float = Field(description="Ah: NaN (Webots' energy is in J; without a voltage, no Ah)")
    capacity: float = Field(description="Ah: NaN")
    design_capacity: float = Field(description="Ah: NaN")
    percentage: float = Field(description="the energy ÷ the maximum (the battery's first two values), 0..1; "
                                          "NaN without a positive maximum")
    power_supply_status: int = Field(ge=0, le=255, description="1 charging, 2 discharging, 3 not charging, 4 full")
    power_supply_health: int = Field(ge=0, le=255, description="0: unknown")
    power_supply_technology: int = Field(ge=0, le=255, description="0: unknown")
    present: bool = Field(description="true")
    cell_voltage: bytes = Field(description="<f4[]: empty")
    cell_temperature: bytes = Field(description="<f4[]: empty")
    location: str = ""
    serial_number: str = ""
    energy: float = Field(default=math.nan,
                          description="J: Sensorium's own field (ROS's message has none in joules, so the ROS 2 export "
                                      "and Foxglove's CDR leave it out): the energy at the sample, what "
                                      "battery_sensor_get_value reads then, with or without a maximum")


class Envelope(Msg):
    """The second frame of every topic message."""

    type: str = Field(description="ROS type name, e.g. sensor_msgs/msg/Range")
    seq: int = Field(ge=0, lt=1 << 64, description="per topic, from 0; a gap means dropped messages")
    stamp_ns: int = Field(description="simulated time of the data (ns)")


ILLUMINANCE = "sensor_msgs/msg/Illuminance"
RANGE = "sensor_msgs/msg/Range"
IMAGE = "sensor_msgs/msg/Image"
LASER_SCAN = "sensor_msgs/msg/LaserScan"
POINT_CLOUD = "sensor_msgs/msg/PointCloud"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
CLOCK = "rosgraph_msgs/msg/Clock"
JOINT_STATE = "sensor_msgs/msg/JointState"
COLOR_RGBA = "std_msgs/msg/ColorRGBA"
POINT_STAMPED = "geometry_msgs/msg/PointStamped"
VECTOR3_STAMPED = "geometry_msgs/msg/Vector3Stamped"
NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"
FLOAT64 = "std_msgs/msg/Float64"
IMU = "sensor_msgs/msg/Imu"
MAGNETIC_FIELD = "sensor_msgs/msg/MagneticField"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
RADAR_SCAN = "radar_msgs/msg/RadarScan"
STRING = "std_msgs/msg/String"
BATTERY_STATE = "sensor_msgs/msg/BatteryState"

MESSAGE_TYPES: dict[str, type[Msg]] = {
    ILLUMINANCE: Illuminance,
    RANGE: Range,
    IMAGE: Image,
    LASER_SCAN: LaserScan,
    POINT_CLOUD: PointCloud,
    POSE_STAMPED: PoseStamped,
    CLOCK: Clock,
    JOINT_STATE: JointState,
    COLOR_RGBA: ColorRGBA,
    POINT_STAMPED: PointStamped,
    VECTOR3_STAMPED: Vector3Stamped,
    NAV_SAT_FIX: NavSatFix,
    FLOAT64: Float64,
    IMU: Imu,
    MAGNETIC_FIELD: MagneticField,
    CAMERA_INFO: CameraInfo,
    RADAR_SCAN: RadarScan,
    STRING: String,
    BATTERY_STATE: BatteryState,
}
"""ROS type name → model, for every topic the server publishes."""


def field_order(model: type[Msg]) -> list[str]:
    """The wire keys of a message, in order."""
    return list(model.model_fields)


def validate(type_name: str, body: dict) -> Msg:
    """Validate a decoded topic body against its model (raises ``KeyError`` for an unknown type,
    ``pydantic.ValidationError`` for a bad body)."""
    return MESSAGE_TYPES[type_name].model_validate(body)
