"""Device kinds: one declaration per Webots device type, which the rest of Sensorium follows.

A :class:`DeviceKind` names everything about a device type that is not its formulas:

* ``type`` — the Webots node type (``device:`` in a world file) and ``node`` — Webots'
  ``WB_NODE_*`` value (``wb_device_get_node_type``), the client-visible table;
* ``model`` — its world-file model in :mod:`sensorium.schemas.world` (``None``: listed, not simulated);
* ``implementation`` — ``"module:Class"`` of the simulation's device class (it holds the state and
  calls the pure model of ``server/devices/``), resolved by the simulation when a world has one;
* ``services`` — the device-scope service items it offers (``/<robot>/<device>/<item>``; the
  arguments and results are the :data:`sensorium.schemas.services.SERVICES` entry of that item,
  the handler is the daemon's ``_dev_<item>``, or ``_motor_<item>`` for a motor);
* ``topics`` — its topics (``/<robot>/<device>/<item>``), each with its ROS-shaped message type,
  which is also the ROS 2 type a bag export writes, and the QoS a ROS 2 driver offers;
* ``rays`` — an upper bound of the rays one measurement casts (world limits add them up), and
  ``ray_bound`` the per-device limit it must stay under;
* ``description`` — what ``attach`` tells a controller about it (a model in ``services.py``).

The daemon's routing (``services.Core._routes``), the topic table (``daemon/topics.py``), the ROS 2
export's QoS table, the world limits and the client's node-type table (``tests/test_device_kinds.py``
keeps the client copies equal) all read :data:`KINDS`. No I/O, no server imports.
"""

from __future__ import annotations

import builtins
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm

__all__ = ["DeviceKind", "KINDS", "TopicDecl", "WEBOTS_NODE_TYPES", "kind", "node_type", "register"]


# Webots' WbNodeType, in Webots' order (include/controller/c/webots/nodes.h, R2023b on): the value of
# WB_NODE_<NAME> is the position in this list. Facts only: the names and their order.
_WEBOTS_NODE_ORDER = (
    "NO_NODE",
    "APPEARANCE", "BACKGROUND", "BILLBOARD", "BOX", "CAD_SHAPE", "CAPSULE", "COLOR", "CONE", "COORDINATE",
    "CYLINDER", "DIRECTIONAL_LIGHT", "ELEVATION_GRID", "FOG", "GROUP", "IMAGE_TEXTURE", "INDEXED_FACE_SET",
    "INDEXED_LINE_SET", "MATERIAL", "MESH", "MUSCLE", "NORMAL", "PBR_APPEARANCE", "PLANE", "POINT_LIGHT",
    "POINT_SET", "POSE", "SHAPE", "SPHERE", "SPOT_LIGHT", "TEXTURE_COORDINATE", "TEXTURE_TRANSFORM", "TRANSFORM",
    "VIEWPOINT",
    "ROBOT",
    "ACCELEROMETER", "ALTIMETER", "BRAKE", "CAMERA", "COMPASS", "CONNECTOR", "DISPLAY", "DISTANCE_SENSOR",
    "EMITTER", "GPS", "GYRO", "INERTIAL_UNIT", "LED", "LIDAR", "LIGHT_SENSOR", "LINEAR_MOTOR", "PEN",
    "POSITION_SENSOR", "PROPELLER", "RADAR", "RANGE_FINDER", "RECEIVER", "ROTATIONAL_MOTOR", "SKIN", "SPEAKER",
    "TOUCH_SENSOR", "VACUUM_GRIPPER",
    "BALL_JOINT", "BALL_JOINT_PARAMETERS", "CHARGER", "CONTACT_PROPERTIES", "DAMPING", "FLUID", "FOCUS",
    "HINGE_JOINT", "HINGE_JOINT_PARAMETERS", "HINGE_2_JOINT", "IMMERSION_PROPERTIES", "JOINT_PARAMETERS", "LENS",
    "LENS_FLARE", "PHYSICS", "RECOGNITION", "SLIDER_JOINT", "SLOT", "SOLID", "SOLID_REFERENCE", "TRACK",
    "TRACK_WHEEL", "WORLD_INFO", "ZOOM",
    "MICROPHONE", "RADIO",
)
WEBOTS_NODE_TYPES: dict[str, int] = {f"WB_NODE_{name}": i for i, name in enumerate(_WEBOTS_NODE_ORDER)}
"""``WB_NODE_*`` name → Webots' value."""


def node_type(type_name: str) -> int:
    """Webots' ``WB_NODE_*`` value of a node type named as in a world file (``"DistanceSensor"``)."""
    snake = "".join("_" + ch if ch.isupper() and i and not type_name[i - 1].isupper() else ch
                    for i, ch in enumerate(type_name)).upper()
    return WEBOTS_NODE_TYPES[f"WB_NODE_{snake}"]


@dataclass(frozen=True, slots=True)
class TopicDecl:
    """One topic of a device: ``/<robot>/<device>/<item>`` carrying ``message`` (a type of
    :data:`sensorium.schemas.messages.MESSAGE_TYPES`, a ROS 2 type name, exported as is).
    ``reading``: the device attribute it publishes; ``exists(config, world_info)``: whether a
    device of this configuration in this world has the topic (default: always); ``sensor_qos``: a ROS 2 driver offers it with
    SensorDataQoS (best effort, depth 5), else the default QoS(10)."""

    item: str
    message: str
    reading: str = "value"
    exists: Callable[[Any, Any], bool] | None = None
    sensor_qos: bool = True


@dataclass(frozen=True, slots=True)
class DeviceKind:
    """One Webots device type (see the module docstring for what each field drives)."""

    type: str
    model: builtins.type | None                         # the world-file model (schemas/world.py)
    implementation: str | None = None
    services: tuple[str, ...] = ()
    topics: tuple[TopicDecl, ...] = ()
    rays: Callable[[Any, int], int] | None = None       # (config, number of lights) -> rays per measurement
    ray_bound: tuple[str, str, str] | None = None       # (field in the message, what is counted, WorldLimits bound)
    description: str | None = None                      # services.py model name of its attach description
    motor: bool = False                                 # a motor: services go to ``_motor_<item>``

    @property
    def simulated(self) -> bool:
        return self.implementation is not None

    @property
    def node(self) -> int:
        return node_type(self.type)

    @property
    def node_name(self) -> str:
        return f"WB_NODE_{_WEBOTS_NODE_ORDER[self.node]}"


KINDS: dict[str, DeviceKind] = {}
"""Every device kind by type name, in registration order."""


def register(k: DeviceKind) -> DeviceKind:
    """Add a kind (a test may add a toy one; a name is registered once)."""
    if k.type in KINDS and KINDS[k.type] is not k:
        raise ValueError(f"device kind {k.type!r} is already registered")
    node_type(k.type)                        # a Webots node type, or KeyError
    KINDS[k.type] = k
    return k


def kind(type_name: str) -> DeviceKind:
    try:
        return KINDS[type_name]
    except KeyError:
        raise KeyError(f"no device kind {type_name!r} (kinds: {', '.join(KINDS)})") from None


# ---------------------------------------------------------------------- the simulated kinds

_SENSOR = ("enable", "get_sampling_period")
_SIM = "sensorium.server.sim.sensors:"


def _laser_scan(cfg: Any, world_info: Any) -> bool:
    # one layer, cylindrical: the beams are at equal angles (a LaserScan can say them)
    return cfg.number_of_layers == 1 and cfg.projection == "cylindrical"


register(DeviceKind(
    "LightSensor", wm.LightSensor, _SIM + "LightSensor",
    services=(*_SENSOR, "get_lookup_table", "get_value"),
    topics=(TopicDecl("value", msgs.ILLUMINANCE),),
    rays=lambda cfg, lights: lights if cfg.occlusion else 0,
    description="LightSensorDescription"))
register(DeviceKind(
    "DistanceSensor", wm.DistanceSensor, _SIM + "DistanceSensor",
    services=(*_SENSOR, "get_lookup_table", "get_min_value", "get_max_value", "get_aperture", "get_type", "get_value"),
    topics=(TopicDecl("value", msgs.RANGE),),
    rays=lambda cfg, lights: max(1, int(cfg.number_of_rays)),    # an upper bound of the rays Webots casts
    ray_bound=(".number_of_rays", "rays:", "rays_per_sensor"),
    description="DistanceSensorDescription"))
register(DeviceKind(
    "Lidar", wm.Lidar, _SIM + "Lidar",
    services=(*_SENSOR, "get_info", "enable_point_cloud", "is_point_cloud_enabled", "get_frequency_info",
              "set_frequency", "get_layer_range_image", "get_layer_point_cloud"),
    topics=(TopicDecl("range_image", msgs.IMAGE, "range_image"),
            TopicDecl("laser_scan", msgs.LASER_SCAN, "range_image", exists=_laser_scan),
            TopicDecl("point_cloud", msgs.POINT_CLOUD, "point_cloud")),
    rays=lambda cfg, lights: int(cfg.horizontal_resolution) * int(cfg.number_of_layers),
    ray_bound=("", "beams (horizontal_resolution × number_of_layers):", "beams_per_lidar"),
    description="LidarDescription"))
register(DeviceKind(
    "PositionSensor", wm.PositionSensor, _SIM + "PositionSensor",
    services=(*_SENSOR, "get_value"),
    topics=(TopicDecl("value", msgs.JOINT_STATE, sensor_qos=False),),
    description="PositionSensorDescription"))
register(DeviceKind(
    "LED", wm.LED, _SIM + "LED",
    services=("set", "get"),
    topics=(TopicDecl("value", msgs.COLOR_RGBA, sensor_qos=False),),
    description="LEDDescription"))
register(DeviceKind(
    "GPS", wm.GPS, _SIM + "GPS",
    services=(*_SENSOR, "get_values", "get_speed", "get_speed_vector", "get_coordinate_system"),
    topics=(TopicDecl("values", msgs.NAV_SAT_FIX, "values", exists=lambda cfg, wi: wi.gps_coordinate_system == "WGS84"),
            TopicDecl("values", msgs.POINT_STAMPED, "values", exists=lambda cfg, wi: wi.gps_coordinate_system == "local"),
            TopicDecl("speed", msgs.FLOAT64, "speed"),
            TopicDecl("speed_vector", msgs.VECTOR3_STAMPED, "speed_vector")),
    description="GPSDescription"))
register(DeviceKind(
    "InertialUnit", wm.InertialUnit, _SIM + "InertialUnit",
    services=(*_SENSOR, "get_roll_pitch_yaw", "get_quaternion", "get_noise"),
    topics=(TopicDecl("quaternion", msgs.IMU, "quaternion"),),
    description="InertialUnitDescription"))
register(DeviceKind(
    "Compass", wm.Compass, _SIM + "Compass",
    services=(*_SENSOR, "get_values", "get_lookup_table"),
    topics=(TopicDecl("values", msgs.MAGNETIC_FIELD, "values"),),
    description="CompassDescription"))
register(DeviceKind(
    "Accelerometer", wm.Accelerometer, _SIM + "Accelerometer",
    services=(*_SENSOR, "get_values", "get_lookup_table"),
    topics=(TopicDecl("values", msgs.VECTOR3_STAMPED, "values"),),
    description="AccelerometerDescription"))
register(DeviceKind(
    "Gyro", wm.Gyro, _SIM + "Gyro",
    services=(*_SENSOR, "get_values", "get_lookup_table"),
    topics=(TopicDecl("values", msgs.VECTOR3_STAMPED, "values"),),
    description="GyroDescription"))
register(DeviceKind(
    "Altimeter", wm.Altimeter, _SIM + "Altimeter",
    services=(*_SENSOR, "get_value"),
    topics=(TopicDecl("value", msgs.FLOAT64, "value"),),
    description="AltimeterDescription"))
register(DeviceKind(
    "TouchSensor", wm.TouchSensor, _SIM + "TouchSensor",
    services=(*_SENSOR, "get_value", "get_values", "get_type", "get_lookup_table"),
    topics=(TopicDecl("value", msgs.FLOAT64, "value", exists=lambda cfg, wi: cfg.type != "force-3d"),
            TopicDecl("values", msgs.VECTOR3_STAMPED, "values", exists=lambda cfg, wi: cfg.type == "force-3d")),
    description="TouchSensorDescription"))
register(DeviceKind(
    "Pen", wm.Pen, "sensorium.server.sim.pen:Pen",
    services=("write", "set_ink_color"),
    topics=(TopicDecl("stroke", msgs.POINT_STAMPED, "stroke"),
            TopicDecl("ink", msgs.COLOR_RGBA, "ink", sensor_qos=False)),
    rays=lambda cfg, lights: 1,                  # one ray per basic step while it writes
    description="PenDescription"))
register(DeviceKind(
    "RangeFinder", wm.RangeFinder, "sensorium.server.sim.cameras:RangeFinder",
    services=_SENSOR,
    topics=(TopicDecl("range_image", msgs.IMAGE, "range_image"),
            TopicDecl("camera_info", msgs.CAMERA_INFO, "range_image", exists=lambda cfg, wi: cfg.projection == "planar")),
    rays=lambda cfg, lights: int(cfg.width) * int(cfg.height),
    ray_bound=("", "pixels (width × height):", "rays_per_image"),
    description="RangeFinderDescription"))
register(DeviceKind(
    "Camera", wm.Camera, "sensorium.server.sim.cameras:Camera",
    services=(*_SENSOR, "set_exposure", "set_fov", "recognition_enable", "get_recognition_sampling_period",
              "enable_segmentation", "is_segmentation_enabled", "get_recognition_objects"),
    topics=(TopicDecl("image", msgs.IMAGE, "image"),
            TopicDecl("camera_info", msgs.CAMERA_INFO, "image", exists=lambda cfg, wi: cfg.projection == "planar"),
            TopicDecl("segmentation_image", msgs.IMAGE, "segmentation_image",
                      exists=lambda cfg, wi: cfg.recognition is not None and cfg.recognition.segmentation)),
    rays=lambda cfg, lights: int(cfg.width) * int(cfg.height) * (4 if cfg.anti_aliasing else 1),
    ray_bound=("", "rays (width × height, × 4 anti-aliased):", "rays_per_image"),
    description="CameraDescription"))
register(DeviceKind(
    "Radar", wm.Radar, "sensorium.server.sim.radar:Radar",
    services=(*_SENSOR, "get_targets"),
    topics=(TopicDecl("targets", msgs.RADAR_SCAN, "targets"),),
    description="RadarDescription"))
# Emitter and Receiver (server/sim/radio.py): packets travel with step requests and replies, no topics
# (a packet is the receiving controller's, taken from the receiver when it reads it).
register(DeviceKind(
    "Emitter", wm.Emitter, "sensorium.server.sim.radio:Emitter",
    services=("get_channel", "set_channel", "get_range", "set_range", "get_buffer_size"),
    description="EmitterDescription"))
register(DeviceKind(
    "Receiver", wm.Receiver, "sensorium.server.sim.radio:Receiver",
    services=(*_SENSOR, "get_channel", "set_channel", "get_buffer_size"),
    description="ReceiverDescription"))
register(DeviceKind(
    "Display", wm.Display, "sensorium.server.sim.display:Display",
    services=("draw",),
    topics=(TopicDecl("image", msgs.IMAGE, "image"),),
    description="DisplayDescription"))
# VacuumGripper and Speaker (server/sim/vacuum.py, server/sim/speaker.py): the pump and the sounds are
# commands answered at once; the presence is a sensor; the speaker's playing sounds travel with step replies.
register(DeviceKind(
    "VacuumGripper", wm.VacuumGripper, "sensorium.server.sim.vacuum:VacuumGripper",
    services=(*_SENSOR, "set_on"),
    topics=(TopicDecl("presence", msgs.FLOAT64, "value"),),
    description="VacuumGripperDescription"))
register(DeviceKind(
    "Speaker", wm.Speaker, "sensorium.server.sim.speaker:Speaker",
    services=("play_sound", "stop", "speak"),
    topics=(TopicDecl("playing", msgs.FLOAT64, "active"),),
    description="SpeakerDescription"))
# Connector (server/sim/connector.py): presence at its sampling period, the lock state the server's;
# Brake: its joint's type and neighbours (its damping constant needs physics: the clients warn).
register(DeviceKind(
    "Connector", wm.Connector, "sensorium.server.sim.connector:Connector",
    services=(*_SENSOR, "get_value", "lock", "unlock", "is_locked"),
    topics=(TopicDecl("presence", msgs.FLOAT64, "value"),),
    description="ConnectorDescription"))
register(DeviceKind(
    "Brake", wm.Brake, "sensorium.server.sim.connector:Brake",
    services=("get_type",),
    description="BrakeDescription"))
# A RotationalMotor is a drive's wheel or steering motor (sim/motion.py owns it) or, any other, a
# joint's motor moved kinematically (sim/joints.py); a LinearMotor is always a joint's.
_MOTOR_SERVICES = ("set_position", "set_velocity", "get_velocity", "get_max_velocity", "get_target_position")
register(DeviceKind(
    "RotationalMotor", wm.RotationalMotor, "sensorium.server.sim.motion:WheelMotor",
    services=_MOTOR_SERVICES, description="MotorDescription", motor=True))
register(DeviceKind(
    "LinearMotor", wm.LinearMotor, "sensorium.server.sim.joints:JointMotor",
    services=_MOTOR_SERVICES, description="JointMotorDescription", motor=True))

# ---------------------------------------------------------------------- listed, not simulated (yet)

for _t in wm.UNSIMULATED_DEVICE_TYPES:
    register(DeviceKind(_t, None))
