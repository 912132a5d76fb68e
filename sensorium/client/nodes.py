"""Webots' node types (``WB_NODE_*``, ``wb_device_get_node_type``), the client's own copy: the
client never imports ``schemas/`` (tests keep this table equal to ``schemas.devices``)."""

from __future__ import annotations

# Webots' WbNodeType, in Webots' order: the value of WB_NODE_<NAME> is the position in this list.
_ORDER = (
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

WEBOTS_NODE_TYPES: dict[str, int] = {f"WB_NODE_{name}": i for i, name in enumerate(_ORDER)}
"""``WB_NODE_*`` name → Webots' value."""

globals().update(WEBOTS_NODE_TYPES)       # WB_NODE_GPS, ... as module constants


def node_type(type_name: str) -> int:
    """Webots' ``WB_NODE_*`` value of a device type name (``"DistanceSensor"``); 0 if unknown."""
    snake = "".join("_" + ch if ch.isupper() and i and not type_name[i - 1].isupper() else ch
                    for i, ch in enumerate(type_name)).upper()
    return WEBOTS_NODE_TYPES.get(f"WB_NODE_{snake}", 0)
