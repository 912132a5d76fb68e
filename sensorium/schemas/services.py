"""Services (PROTOCOL.md §3): request/reply envelopes, error codes, per-service args and results.

Every request and reply shape of the protocol is a model here. :data:`SERVICES` lists each
service once — name pattern, argument model, result model, which devices offer it and whether
the caller must be the robot's attached controller — and the server's handler table is checked
against it, so the protocol page, these models and the server cannot drift apart.

Argument models are strict (no coercion: ``"32"`` is not an int, ``true`` is not 1), refuse
unknown keys and refuse NaN/inf. Vectors are lists because msgpack has no tuples.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import UnionType
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, field_validator, model_validator

from sensorium.schemas.messages import Image, PointCloud
from sensorium.schemas.wire import PROTOCOL_VERSION, ErrorCode

__all__ = ["ErrorCode", "PROTOCOL_VERSION", "SERVICES", "ServiceSpec", "service_names"]

MAX_PERIOD_MS = (1 << 31) - 1
MAX_MOTOR_COMMANDS = 256        # per step request (a robot has a handful of motors)
MAX_EMITTERS = 256              # emitters named in one step request
MAX_DISPLAYS = 64               # displays named in one step request
MAX_WINDOW_TEXT = 1 << 18       # characters of one robot-window text (at most 1 MiB of UTF-8: one request)
MAX_WINDOW_QUEUE = 256          # texts waiting for a robot's controller (window_send)
MAX_WINDOW_QUEUE_CHARS = 1 << 20   # characters of those texts in all
Mode = Literal["fast", "realtime", "pause"]
FieldName = Annotated[str, Field(min_length=1, max_length=256, description=(
    "a Webots field name (translation, rotation, name, children, on, intensity, color, ...: README "
    "'Supervisor' lists which node kind has which; a PROTO's interface field's, up to 256 characters)"))]
Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Vec4 = Annotated[list[float], Field(min_length=4, max_length=4)]


class Args(BaseModel):
    """Base of argument maps."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


class Result(BaseModel):
    """Base of result maps (NaN/inf allowed: sensor values)."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


# ---------------------------------------------------------------------- envelopes

class Request(BaseModel):
    """``{"id", "service", "args"}``: one frame from a DEALER (REQ: after the empty delimiter)."""

    model_config = ConfigDict(extra="allow", strict=True)

    id: int = Field(ge=0, lt=1 << 64)
    service: str = Field(min_length=1)
    args: dict[str, Any]


class ErrorInfo(Result):
    code: int = Field(description="an ErrorCode")
    message: str


class OkReply(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)

    id: int
    ok: Literal[True]
    result: dict[str, Any]


class ErrorReply(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)

    id: int | None = Field(description="null when the request could not be read")
    ok: Literal[False]
    error: ErrorInfo


# ---------------------------------------------------------------------- arguments

class NoArgs(Args):
    pass


class AttachArgs(Args):
    robot: str = Field(min_length=1)


class SessionArgs(Args):
    session: str = Field(min_length=1)


class SetModeArgs(Args):
    mode: Mode


class MotorCommand(Args):
    """One motor's commands with a step request (Webots: what ``setPosition``/``setVelocity`` set
    since the previous step). Either key may be left out."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=True, frozen=True)

    position: float | None = Field(default=None, description="target position (rad); +inf/-inf = velocity control")
    velocity: float | None = Field(default=None, description="rad/s, finite; clamped to maxVelocity")
    acceleration: float | None = Field(default=None, description="a joint motor's setAcceleration: >= 0, or -1 "
                                                                 "(a drive's wheel ignores it)")
    available_force: float | None = Field(default=None, description="a joint motor's setAvailableTorque/Force: >= 0, "
                                                                    "clamped to its maximum (a drive's wheel ignores it)")

    @field_validator("acceleration")
    @classmethod
    def _acceleration(cls, v: float | None) -> float | None:
        if v is not None and not (v == -1.0 or 0.0 <= v < float("inf")):
            raise ValueError("acceleration must be >= 0 and finite, or -1")
        return v

    @field_validator("available_force")
    @classmethod
    def _available(cls, v: float | None) -> float | None:
        if v is not None and not 0.0 <= v < float("inf"):
            raise ValueError("available torque/force must be >= 0 and finite")
        return v

    @field_validator("position")
    @classmethod
    def _not_nan(cls, v: float | None) -> float | None:
        if v is not None and v != v:
            raise ValueError("position must not be NaN")
        return v

    @field_validator("velocity")
    @classmethod
    def _finite(cls, v: float | None) -> float | None:
        if v is not None and (v != v or v in (float("inf"), float("-inf"))):
            raise ValueError("velocity must be finite")
        return v


class PacketOut(Args):
    """One packet a controller's emitter sends with a step request (Webots' C_EMITTER_SEND): its
    bytes and the emitter's channel and range when the controller sent it."""

    data: bytes = Field(min_length=1, description="the packet (at least 1 byte)")
    channel: int = Field(ge=-1, le=(1 << 31) - 1, description="-1: every channel")
    range: float = Field(description="m; -1: unlimited")

    @field_validator("range")
    @classmethod
    def _range(cls, v: float) -> float:
        if v != -1.0 and not v >= 0.0:
            raise ValueError("range must be -1 or >= 0")
        return v


class StepArgs(Args):
    duration: int | None = Field(default=None, ge=0, le=MAX_PERIOD_MS,
                                 description="ms; default: one basic step. Not a multiple of the basic step: rounded "
                                             "up to one (Webots). 0: apply the motor commands and answer at once with "
                                             "the values not yet delivered, without advancing time (Webots' step(0))")
    motors: dict[str, MotorCommand] | None = Field(
        default=None, description="motor name -> commands, applied when the request arrives (before the world advances); "
                                  f"at most {MAX_MOTOR_COMMANDS}")
    emitters: dict[str, list[PacketOut]] | None = Field(
        default=None, description="emitter name -> the packets its controller sent since the previous step (as its "
                                  "baud rate let them leave), in order; they travel at the next basic step")
    displays: dict[str, list[list[Any]]] | None = Field(
        default=None, description="display name -> its drawing commands since the previous step, in order (README "
                                  "'The Display' lists them: [\"line\", x1, y1, x2, y2], ...); drawn when the request "
                                  f"arrives; at most {MAX_DISPLAYS} displays")

    @model_validator(mode="before")
    @classmethod
    def _few_motor_commands(cls, data: Any) -> Any:
        # counted before each command is validated: a step carrying thousands costs nothing
        motors = data.get("motors") if isinstance(data, dict) else None
        if isinstance(motors, dict) and len(motors) > MAX_MOTOR_COMMANDS:
            raise ValueError(f"motors: {len(motors)} commands, at most {MAX_MOTOR_COMMANDS} per step")
        emitters = data.get("emitters") if isinstance(data, dict) else None
        if isinstance(emitters, dict) and len(emitters) > MAX_EMITTERS:
            raise ValueError(f"emitters: {len(emitters)} emitters, at most {MAX_EMITTERS} per step")
        displays = data.get("displays") if isinstance(data, dict) else None
        if isinstance(displays, dict) and len(displays) > MAX_DISPLAYS:
            raise ValueError(f"displays: {len(displays)} displays, at most {MAX_DISPLAYS} per step")
        return data


class DrawArgs(Args):
    """A Display's drawing commands sent at once (``wb_display_image_save`` flushes them, as Webots'
    libController does) and, with ``save``, the image to send back."""

    commands: list[list[Any]] = Field(default_factory=list, description="as a step request's 'displays' entry")
    save: int | None = Field(default=None, ge=0, lt=1 << 31, description="0: the display as shown; n: image n")


class ChannelArgs(Args):
    value: int = Field(ge=-1, le=(1 << 31) - 1, description="-1: every channel")


class RangeArgs(Args):
    value: float = Field(description="m; -1: the maximum range")


class TimeStepArgs(Args):
    value: int = Field(ge=0, le=MAX_PERIOD_MS, description="ms, rounded up to a multiple of the basic time step; "
                                                          "0 = one basic step")


class SetPoseArgs(Args):
    translation: Vec3 | None = Field(default=None, description="left out: keep the current translation")
    rotation: Vec4 | None = Field(default=None, description="Webots axis-angle: axis x, y, z, angle (rad)")
    quaternion: Vec4 | None = Field(default=None, description="x, y, z, w")


class EnableArgs(Args):
    value: int = Field(ge=0, le=MAX_PERIOD_MS, description="sampling period (ms); 0 disables")


class BoolArgs(Args):
    value: bool


class FrequencyArgs(Args):
    value: float = Field(description="Hz, within [minFrequency, maxFrequency]")


class ExposureArgs(Args):
    value: float = Field(ge=0.0, description="the camera's photometric exposure (Webots' exposure, >= 0)")


class FovArgs(Args):
    value: float = Field(description="rad, within the camera's Zoom range [min_fov, max_fov]")


class LayerArgs(Args):
    layer: int = Field(ge=0, lt=1 << 31)


class MotorPositionArgs(Args):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=True, frozen=True)

    value: float = Field(description="target position (rad); +inf/-inf = velocity control")

    @field_validator("value")
    @classmethod
    def _not_nan(cls, v: float) -> float:
        if v != v:
            raise ValueError("position must not be NaN")
        return v


class MotorVelocityArgs(Args):
    value: float = Field(description="rad/s, finite; clamped to maxVelocity")


class IntArgs(Args):
    value: int = Field(ge=-(1 << 31), lt=1 << 31)


class InkColorArgs(Args):
    """``wb_pen_set_ink_color``: Webots' 0xRRGGBB colour and the ink density (clamped to [0, 1])."""

    color: int = Field(ge=0, le=0xFFFFFF, description="0xRRGGBB (each channel byte / 255)")
    density: float = Field(description="0 transparent ... 1 opaque; clamped to [0, 1] (Webots)")


class PlaySoundArgs(Args):
    """``wb_speaker_play_sound`` on one speaker: the sound (its file name, the key of ``stop`` and of
    the step reading), the WAV's frames and rate (the client reads the file: a sound plays
    ``frames / (rate * pitch)`` s of simulated time), and Webots' volume, pitch, balance, loop and side."""

    sound: str = Field(min_length=1, max_length=4096)
    frames: int = Field(ge=0, lt=1 << 62, description="sample frames in the WAV file")
    rate: int = Field(ge=1, lt=1 << 31, description="frames per second")
    volume: float = Field(ge=0.0, le=1.0)
    pitch: float = Field(ge=0.0, le=1e9, description="playback speed factor (0: OpenAL refuses it, 1 is kept)")
    balance: float = Field(ge=-1.0, le=1.0)
    loop: bool
    side: int = Field(ge=-1, le=1, description="0: both channels, -1: left, 1: right (libController's side)")


class SpeakArgs(Args):
    text: str = Field(max_length=1 << 20)
    volume: float = Field(ge=0.0, le=1.0)


class StringArgs(Args):
    value: str = Field(max_length=1 << 20)


class WindowTextArgs(Args):
    """A robot-window text: from the controller (``wwi_send``, Webots' ``wb_robot_wwi_send_text``) or
    to it (``window_send``, what a robot window's page sends)."""

    text: str = Field(max_length=MAX_WINDOW_TEXT, description=f"at most {MAX_WINDOW_TEXT:,} characters")


class WindowQueuedResult(Result):
    queued: int = Field(description="the texts now waiting for the robot's controller, this one included")


class UrdfArgs(Args):
    prefix: str = Field(default="", max_length=4096, description="put before every link and joint name "
                        "(Webots wb_robot_get_urdf's prefix)")


class NodeNameArgs(Args):
    name: str = Field(min_length=1, max_length=4096, description="a node's DEF name, or a dotted path of DEF names "
                      "(A.B: B a direct child of A); else a robot's, solid's or light's name")


class ProtoDefArgs(Args):
    node: NodeId = Field(description="a PROTO instance (Webots wb_supervisor_node_get_from_proto_def's node)")
    name: str = Field(min_length=1, max_length=4096, description="a DEF name written in the instance's PROTO body")


class NodeDeviceArgs(Args):
    device: str = Field(min_length=1, max_length=4096, description="the calling robot's device name (Webots "
                        "wb_supervisor_node_get_from_device)")


class NodeIdArgs(Args):
    id: int = Field(ge=0, lt=1 << 31, description="a node id (0: the root; Webots wb_supervisor_node_get_from_id)")


NodeId = Annotated[int, Field(ge=0, lt=1 << 31, description="a node id from get_root / get_from_def / get_self / "
                                                           "get_from_id (0: the root)")]


class NodeArgs(Args):
    node: NodeId


_LEVEL = ("whose fields: -1 the node's (a PROTO instance's: its PROTO's interface fields, Webots' getField), 0 its "
          "base node's (getBaseNodeField), k >= 1 the k-th PROTO of its chain (1 its own PROTO, 2 the PROTO that one "
          "is built on, ...: getProto().getField, getParent())")


class ContactPointsArgs(Args):
    node: NodeId = Field(description="a top-level robot or solid")
    include_descendants: bool = Field(default=False, description="the solids inside it touch too (Webots' "
                                      "includeDescendants): a robot's wheels, a nested solid")


class FieldArgs(Args):
    node: NodeId
    field: FieldName
    level: int = Field(default=-1, ge=-1, le=16, description=_LEVEL)


class SetFieldArgs(Args):
    node: NodeId
    field: FieldName
    level: int = Field(default=-1, ge=-1, le=16, description=_LEVEL)
    value: bool | int | float | Annotated[list[float], Field(min_length=2, max_length=4)] | \
        Annotated[str, Field(max_length=4096)] | None = Field(
        default=None, description="SFBool true/false; SFFloat a number; SFVec3f/SFColor 3 numbers; SFRotation axis "
        "x, y, z, angle; SFInt32 a whole number, SFVec2f 2 numbers, SFString a string (a robot's customData and controller, a top-level solid's PROTO fields); an MF field's item (with index): MFBool true/false, MFInt32 a whole number, MFFloat a "
        "number, MFVec2f 2 numbers, MFVec3f/MFColor 3 numbers, MFRotation 4, MFString a string; none to remove")
    index: int | None = Field(default=None, ge=-(1 << 31), lt=1 << 31, description=(
        "an MF field's item (negative from the end, as Webots): setMF*, insertMF* (0 first, -1 after the last), "
        "removeMF; absent: the field as a whole"))
    op: Literal["set", "insert", "remove"] = Field(default="set", description="with index: what is done to the item")


class ProtoArgs(Args):
    node: NodeId
    level: int = Field(default=1, ge=0, le=16, description="the k-th PROTO of the node's chain: 1 its own PROTO "
                       "(Webots' getProto()), 2 the PROTO that one is built on (getParent()), ...; 0 the base node "
                       "(its base type name and the fields served here, in Webots' declaration order)")


class SetVisibilityArgs(Args):
    node: NodeId = Field(description="the node to hide or show, with what is inside it (a robot, a solid, a Shape, ...)")
    from_node: NodeId = Field(description="the Camera, Lidar or RangeFinder node (a robot's device) or the Viewpoint "
                              "it is hidden from or shown to")
    visible: bool


class SetJointPositionArgs(Args):
    node: NodeId = Field(description="a joint node inside a robot: HingeJoint, SliderJoint, Hinge2Joint, BallJoint")
    position: float = Field(description="the joint's new position (rad, or m on a slider): a finite number")
    index: int = Field(default=1, ge=-(1 << 31), lt=1 << 31, description=(
        "the joint's axis: 1 (HingeJoint, SliderJoint), 1 or 2 (Hinge2Joint), 1, 2 or 3 (BallJoint)"))


class NodeStateArgs(Args):
    node: NodeId = Field(description="a robot, a top-level solid, or a node inside one")
    state: str = Field(max_length=1024, description="the state's name ('__init__': as the world loaded)")


class ImportNodeArgs(Args):
    node: NodeId = Field(description="the node whose field takes the nodes: the root (0), or an imported line or "
                         "point set (importSFNodeFromString)")
    field: FieldName = Field(description="its MFNode field: 'children'; or the set's empty SFNode 'coord' (a "
                             "Coordinate) or 'color' (a Color): one node, position ignored")
    position: int = Field(ge=-(1 << 31), lt=1 << 31, description=(
        "where in the list: 0 first, -1 after the last, -2 before the last (Webots); past an end: that end"))
    node_string: str = Field(max_length=1 << 24, description=(
        "Webots nodes as a .wbt file writes them: solids (or PROTO instances that are solids, of PROTOs the "
        "world file declares) and lights"))


class IntArrayValue(Result):
    value: list[int]


class SimulationModeArgs(Args):
    mode: int = Field(ge=0, le=2, description="Webots WB_SUPERVISOR_SIMULATION_MODE_*: 0 pause, 1 real time, 2 fast")


class SimulationQuitArgs(Args):
    """``wb_supervisor_simulation_quit``: the simulation ends for every controller and the server exits."""

    status: int = Field(ge=-2**31, le=2**31 - 1, description="the exit status of `sensorium run`/`serve` (Webots': its own)")


class WorldLoadArgs(Args):
    """``wb_supervisor_world_load``: the world ``sensorium run`` loads next."""

    filename: str = Field(min_length=1, max_length=4096, description=(
        "the world file, relative to the calling controller's folder (Webots' rule); within the folder of the world "
        "`sensorium run` was started with"))


class SetLabelArgs(Args):
    """``wb_supervisor_set_label``: a text over the exported picture (README 'Supervisor')."""

    id: int = Field(ge=0, le=65534, description="the label's id (Webots: 0..65534; setting it again replaces it)")
    text: str = Field(max_length=1024, description="characters 32..127 (and newlines)")
    x: float = Field(ge=0.0, le=1.0, description="its left edge, a fraction of the image's width")
    y: float = Field(ge=0.0, le=1.0, description="its top edge, a fraction of the image's height")
    size: float = Field(ge=0.0, le=1.0, description="its height, a fraction of the image's height")
    color: int = Field(ge=0, le=0xFFFFFF, description="0xRRGGBB")
    transparency: float = Field(ge=0.0, le=1.0, description="0 opaque, 1 invisible")
    font: str = Field(max_length=256, description="Webots' font name (kept; one bitmap font draws every label here)")


class MovieStartArgs(Args):
    """``wb_supervisor_movie_start_recording``: the movie's frames rendered on the server from now on."""

    width: int = Field(ge=1, le=4096, description="frame width in pixels (even)")
    height: int = Field(ge=1, le=4096, description="frame height in pixels (even)")
    acceleration: int = Field(ge=1, le=10_000, description="simulated time per movie time (Webots' acceleration)")
    caption: bool = Field(default=False, description="Webots' caption: the acceleration at the top right")


# ---------------------------------------------------------------------- results

class Empty(Result):
    pass


class DeviceRef(Result):
    """A robot's device as ``get_info`` lists it (every device, in Webots' tree order)."""

    name: str
    type: str = Field(description="the Webots node type (a kind of schemas.devices)")
    model: str = ""
    index: int = Field(ge=0, description="Webots' device index (wb_robot_get_device_by_index)")
    simulated: bool = True


class RobotInfo(Result):
    name: str
    controller: str = "<extern>"
    synchronization: bool
    attached: bool
    devices: list[DeviceRef]


class TopicRef(Result):
    name: str
    type: str


class InfoResult(Result):
    protocol: int = PROTOCOL_VERSION
    version: str
    world: str
    basic_time_step: int = Field(description="ms")
    time_ms: int
    mode: Mode
    real_time_factor: float = Field(description="simulated / wall time over the last second (0 while idle)")
    pub_endpoint: str
    robots: list[RobotInfo]
    topics: list[TopicRef]


class _Entry(Result):
    """What every device entry says: Webots' identity of the device (``wb_device_get_*``)."""

    name: str
    model: str = Field(default="", description="the device's Webots 'model' field (wb_device_get_model)")
    index: int = Field(ge=0, description="position in the robot's device list: Webots' tree order, unsimulated devices included")
    simulated: bool = Field(default=True, description="false: listed, its functions answer Webots' 'no value'")


class UnsimulatedDescription(_Entry):
    """A device Sensorium lists but does not simulate (a controller gets Webots' "no value")."""

    type: str
    simulated: bool = False


class DisplayDescription(_Entry):
    """A Display: its size (the image it draws on)."""

    type: Literal["Display"]
    width: int = Field(description="pixels (wb_display_get_width)")
    height: int = Field(description="pixels (wb_display_get_height)")


class LightSensorDescription(_Entry):
    type: Literal["LightSensor"]
    sampling_period: int
    lookup_table: list[float] = Field(description="flat [x0, y0, n0, x1, ...]")


class DistanceSensorDescription(_Entry):
    type: Literal["DistanceSensor"]
    sampling_period: int
    lookup_table: list[float]
    min_value: float
    max_value: float
    aperture: float
    sensor_type: int = Field(description="get_type: 0 generic, 1 infra-red, 2 sonar, 3 laser")


class LidarDescription(_Entry):
    type: Literal["Lidar"]
    sampling_period: int
    horizontalResolution: int
    numberOfLayers: int
    fov: float
    verticalFov: float
    minRange: float
    maxRange: float
    frequency: float
    minFrequency: float
    maxFrequency: float
    point_cloud_enabled: bool


class RangeFinderDescription(_Entry):
    type: Literal["RangeFinder"]
    sampling_period: int
    width: int
    height: int
    fov: float = Field(description="rad, horizontal")
    near: float
    minRange: float
    maxRange: float
    projection: str = Field(description="planar, cylindrical or spherical")


class CameraDescription(_Entry):
    type: Literal["Camera"]
    sampling_period: int
    width: int
    height: int
    fov: float = Field(description="rad, horizontal")
    near: float
    min_fov: float = Field(description="rad: the Zoom's minFieldOfView (fov without a Zoom)")
    max_fov: float = Field(description="rad: the Zoom's maxFieldOfView (fov without a Zoom)")
    far: float = Field(description="0: no far plane")
    exposure: float
    projection: str = Field(description="planar, cylindrical or spherical")
    anti_aliasing: bool
    noise: float
    has_recognition: bool = Field(description="wb_camera_has_recognition: a Recognition node")
    has_segmentation: bool = Field(description="wb_camera_recognition_has_segmentation")
    recognition_sampling_period: int = Field(description="0 at attach")
    segmentation_enabled: bool


class MotorDescription(_Entry):
    type: Literal["RotationalMotor", "LinearMotor"]
    maxVelocity: float = Field(description="rad/s (m/s for a LinearMotor)")
    minPosition: float = Field(description="rad (m); minPosition = maxPosition = 0: no limits (Webots)")
    maxPosition: float
    targetPosition: float = Field(description="rad (m), inf in velocity control (the motor's current command)")
    velocity: float = Field(description="rad/s (m/s) (the motor's current command)")


class JointMotorDescription(MotorDescription):
    """A motor that is no drive's: its joint moves kinematically (Webots' rule without physics)."""

    acceleration: float = Field(description="rad/s² (m/s²); -1: bounded by the available torque/force only")
    maxForce: float = Field(description="maxTorque (N·m) of a RotationalMotor, maxForce (N) of a LinearMotor")
    initialPosition: float = Field(description="the joint's position as loaded: where a simulation reset puts it "
                                               "and its target")
    multiplier: float = Field(default=1.0, description="scales the position and velocity commands it takes "
                                                       "(getMultiplier)")
    coupled: list[str] = Field(default_factory=list, description="the other motors of its coupled group (names "
                               "sharing the part before '::'): a position or velocity given to this motor reaches "
                               "them, each scaled by its own multiplier")


class PositionSensorDescription(_Entry):
    type: Literal["PositionSensor"]
    sampling_period: int
    motor: str = Field(description="the wheel motor on the same joint (Motor.getPositionSensor / getMotor)")
    noise: float
    resolution: float


class GPSDescription(_Entry):
    type: Literal["GPS"]
    sampling_period: int
    coordinate_system: int = Field(description="wb_gps_get_coordinate_system: 0 local, 1 WGS84")
    accuracy: float
    noise_correlation: float
    resolution: float
    speed_noise: float
    speed_resolution: float


class InertialUnitDescription(_Entry):
    type: Literal["InertialUnit"]
    sampling_period: int
    noise: float = Field(description="wb_inertial_unit_get_noise")
    coordinate_system: str = Field(description="ENU or NUE: the roll/pitch/yaw convention")


class CompassDescription(_Entry):
    type: Literal["Compass"]
    sampling_period: int
    lookup_table: list[float] = Field(description="flat [x0, y0, n0, x1, ...]")


class AccelerometerDescription(_Entry):
    type: Literal["Accelerometer"]
    sampling_period: int
    lookup_table: list[float] = Field(description="flat [x0, y0, n0, x1, ...]")


class GyroDescription(_Entry):
    type: Literal["Gyro"]
    sampling_period: int
    lookup_table: list[float] = Field(description="flat [x0, y0, n0, x1, ...]")


class AltimeterDescription(_Entry):
    type: Literal["Altimeter"]
    sampling_period: int
    accuracy: float
    resolution: float


class TouchSensorDescription(_Entry):
    type: Literal["TouchSensor"]
    sampling_period: int
    sensor_type: int = Field(description="get_type: 0 bumper, 1 force, 2 force-3d")
    lookup_table: list[float] = Field(description="flat [x0, y0, n0, x1, ...]")


class RadarDescription(_Entry):
    type: Literal["Radar"]
    sampling_period: int
    min_range: float = Field(description="m (wb_radar_get_min_range)")
    max_range: float = Field(description="m (wb_radar_get_max_range)")
    horizontal_fov: float = Field(description="rad (wb_radar_get_horizontal_fov)")
    vertical_fov: float = Field(description="rad (wb_radar_get_vertical_fov)")


class ConnectorDescription(_Entry):
    type: Literal["Connector"]
    sampling_period: int = Field(description="the presence's (wb_connector_get_presence_sampling_period)")
    connector_type: Literal["symmetric", "active", "passive"]
    is_locked: bool = Field(description="the lock state now (wb_connector_is_locked)")
    auto_lock: bool
    distance_tolerance: float = Field(description="m")
    axis_tolerance: float = Field(description="rad")
    rotation_tolerance: float = Field(description="rad")
    number_of_rotations: int


class BrakeDescription(_Entry):
    type: Literal["Brake"]
    joint_type: int = Field(description="wb_brake_get_type: 0 rotational (WB_ROTATIONAL), 1 linear (WB_LINEAR)")
    motor: str | None = Field(description="the motor on the same joint (wb_brake_get_motor), none: null")
    position_sensor: str | None = Field(description="the PositionSensor on the same joint "
                                                    "(wb_brake_get_position_sensor), none: null")


class EmitterDescription(_Entry):
    type: Literal["Emitter"]
    medium: Literal["radio", "serial", "infra-red"]
    channel: int = Field(description="the current channel (-1: broadcast)")
    range: float = Field(description="m, the current range; -1: unlimited")
    max_range: float = Field(description="m; -1: unlimited")
    aperture: float = Field(description="rad, infra-red cone; -1: every direction")
    buffer_size: int = Field(description="bytes the controller's queue holds; -1: unlimited")
    byte_rate: float = Field(description="bytes per ms the controller may send (baudRate / byteSize / 1000); -1: unlimited")
    allowed_channels: list[int] = Field(description="empty: any channel")


class ReceiverDescription(_Entry):
    type: Literal["Receiver"]
    sampling_period: int
    medium: Literal["radio", "serial", "infra-red"]
    channel: int = Field(description="the current channel (-1: every channel)")
    aperture: float
    buffer_size: int = Field(description="bytes the controller's queue holds; -1: unlimited")
    allowed_channels: list[int]
    signal_strength_noise: float
    direction_noise: float


class VacuumGripperDescription(_Entry):
    type: Literal["VacuumGripper"]
    sampling_period: int
    is_on: bool = Field(description="the pump now (wb_vacuum_gripper_is_on)")
    tensile_strength: float = Field(description="N; -1 infinite")
    shear_strength: float = Field(description="N; -1 infinite")
    contact_points: int


class SpeakerDescription(_Entry):
    type: Literal["Speaker"]
    sounds: list[str] = Field(description="the sounds playing now")
    speaking: bool = Field(description="whether it is speaking now")


class LEDDescription(_Entry):
    type: Literal["LED"]
    value: int = Field(description="the current value (0 off, colour index, or 0xRRGGBB when gradual)")
    color: list[float] = Field(description="flat [r0, g0, b0, r1, ...]")
    gradual: bool


class PenDescription(_Entry):
    type: Literal["Pen"]
    write: bool = Field(description="whether it writes now (wb_pen_write)")
    ink_color: list[float] = Field(description="[r, g, b] in [0, 1], the ink now (wb_pen_set_ink_color)")
    ink_density: float
    lead_size: float = Field(description="m")
    max_distance: float = Field(description="m; <= 0: unlimited")


def _description_tag(v: Any) -> str:
    get = v.get if isinstance(v, dict) else (lambda k, d=None: getattr(v, k, d))
    if get("simulated", True):
        if get("maxForce") is not None:                # a joint's motor (a drive's wheel has no maxForce)
            return "joint motor"
        return str(get("type", ""))
    return "unsimulated"


DeviceDescription = Annotated[
    Annotated[LightSensorDescription, Tag("LightSensor")] | Annotated[DistanceSensorDescription, Tag("DistanceSensor")]
    | Annotated[LidarDescription, Tag("Lidar")] | Annotated[MotorDescription, Tag("RotationalMotor")]
    | Annotated[MotorDescription, Tag("LinearMotor")]
    | Annotated[JointMotorDescription, Tag("joint motor")]
    | Annotated[PositionSensorDescription, Tag("PositionSensor")] | Annotated[LEDDescription, Tag("LED")]
    | Annotated[GPSDescription, Tag("GPS")] | Annotated[InertialUnitDescription, Tag("InertialUnit")]
    | Annotated[CompassDescription, Tag("Compass")] | Annotated[AccelerometerDescription, Tag("Accelerometer")]
    | Annotated[GyroDescription, Tag("Gyro")] | Annotated[AltimeterDescription, Tag("Altimeter")]
    | Annotated[TouchSensorDescription, Tag("TouchSensor")] | Annotated[PenDescription, Tag("Pen")]
    | Annotated[RangeFinderDescription, Tag("RangeFinder")] | Annotated[CameraDescription, Tag("Camera")]
    | Annotated[EmitterDescription, Tag("Emitter")] | Annotated[ReceiverDescription, Tag("Receiver")]
    | Annotated[RadarDescription, Tag("Radar")]
    | Annotated[VacuumGripperDescription, Tag("VacuumGripper")] | Annotated[SpeakerDescription, Tag("Speaker")]
    | Annotated[ConnectorDescription, Tag("Connector")] | Annotated[BrakeDescription, Tag("Brake")]
    | Annotated[DisplayDescription, Tag("Display")] | Annotated[UnsimulatedDescription, Tag("unsimulated")],
    Discriminator(_description_tag)]
"""An ``attach`` device entry: the kind's description (schemas.devices ``description``), or
:class:`UnsimulatedDescription` for a device that is listed only."""


class AckermannDescription(Result):
    """A car-like robot's ``ackermann_drive`` (its world entry): what Webots' vehicle library reads
    from a Car's customData, which the client's ``Driver``/``Car`` work from."""

    wheelbase: float
    track_front: float
    track_rear: float
    front_wheel_radius: float
    rear_wheel_radius: float
    type: Literal["traction", "propulsion", "4x4"]
    max_wheel_speed: float
    max_steering_angle: float
    max_steering_speed: float
    positive_steers: Literal["right", "left"]
    right_steer: str
    left_steer: str
    right_front_wheel: str
    left_front_wheel: str
    right_rear_wheel: str
    left_rear_wheel: str
    forward: tuple[float, float] | tuple[float, float, float] = Field(
        default=(1.0, 0.0), description="the drive's forward direction (x, y) in the robot's frame, or (x, y, z) "
        "for a robot built y-up in a NUE world; the geometry above is in the drive's axes")
    rear_axle_offset: float = Field(default=0.0, description="m, the rear axle's centre along forward from the "
                                    "robot's origin (0: the origin is on it, as in Webots' cars)")
    engine_type: Literal["combustion", "electric", "parallel hybrid", "power-split hybrid"] = Field(
        default="combustion", description="Webots' Car engineType (the vehicle library's getEngineType)")

    @field_validator("forward", mode="before")
    @classmethod
    def _pair(cls, v: Any) -> Any:
        """msgpack gives a list: the pair (or triple) it is."""
        return tuple(v) if isinstance(v, list) else v


class AttachResult(Result):
    session: str
    robot: str
    basic_time_step: int
    time_ms: int
    synchronization: bool
    heartbeat_ms: int
    devices: list[DeviceDescription]
    supervisor: bool = Field(default=False, description="the world lets this robot's controller use Supervisor services")
    model: str = ""
    custom_data: str = ""
    ackermann_drive: AckermannDescription | None = Field(default=None, description="a car-like robot's drive "
                                                        "(the world's ackermann_drive); null for other robots")


class TimeResult(Result):
    time_ms: int


class ModeResult(Result):
    mode: Mode


class ScalarReading(Result):
    value: float = Field(description="NaN before the first measurement")
    is_on: bool | None = Field(default=None, description="VacuumGripper: its pump when the presence was measured")


class LidarReading(Result):
    range_image: bytes = Field(description="little-endian float32[layers][columns]")
    point_cloud: bytes | None = Field(default=None, description="20-byte records x, y, z <f4, layer_id <i4, time <f4; "
                                                                "present while the point cloud is enabled")


class VectorReading(Result):
    """A GPS, InertialUnit, Compass, Accelerometer, Gyro or force-3d TouchSensor reading: the keys
    its getters read (NaN before the first measurement)."""

    values: list[float] | None = Field(default=None, description="GPS, Compass, Accelerometer, Gyro, force-3d TouchSensor")
    speed: float | None = Field(default=None, description="GPS (m/s)")
    speed_vector: list[float] | None = Field(default=None, description="GPS (m/s)")
    quaternion: list[float] | None = Field(default=None, description="InertialUnit: x, y, z, w")
    roll_pitch_yaw: list[float] | None = Field(default=None, description="InertialUnit (rad)")


class PacketIn(Result):
    data: bytes
    signal_strength: float = Field(description="1/r² (r: emitter-receiver distance), with the receiver's noise")
    direction: list[float] = Field(description="unit vector to the emitter in the receiver frame")


class ReceiverReading(Result):
    packets: list[PacketIn] = Field(description="the packets that became readable since the previous reply, oldest first")


class SpeakerReading(Result):
    """A Speaker's state, in the reply of every step that changed it (no enable needed)."""

    sounds: list[str] = Field(description="the sounds still playing (a sound left out is over)")
    speaking: bool = Field(description="whether its text is still being spoken")


class StepResult(Result):
    status: int = Field(description="0; -1 when the server quits; the lateness dt (ms) for asynchronous robots")
    time_ms: int
    values: dict[str, ScalarReading | LidarReading | VectorReading | ReceiverReading | SpeakerReading]
    custom_data: str | None = Field(default=None, description="the robot's customData, when a Supervisor (or a "
                                    "reset) changed it since the controller last had it (getCustomData)")
    robot_window: list[str] | None = Field(default=None, description="the texts sent to the robot's window side "
                                           "(window_send) since the previous reply, oldest first (wwiReceiveText)")


class SuccessResult(Result):
    success: bool


class FloatValue(Result):
    value: float


class DrawResult(Result):
    """``draw``: the saved image when ``save`` was asked (BGRA bytes, rows top first), else none."""

    width: int = Field(default=0, ge=0)
    height: int = Field(default=0, ge=0)
    data: bytes | None = Field(default=None, description="width x height x 4 bytes (B, G, R, A); null: no such image")


class ImageResult(Result):
    """``export_image``: the Viewpoint's picture with the labels over it; the client writes the file."""

    width: int = Field(ge=1)
    height: int = Field(ge=1)
    data: bytes = Field(description="width x height x 3 bytes (R, G, B), rows top first")


class MovieStartResult(Result):
    """``movie_start``: the simulated ms between two frames (the movie runs at acceleration × 1000 / step_ms fps)."""

    step_ms: int = Field(ge=1)


class MovieFramesResult(Result):
    """``movie_frames``: the frames rendered since the last call, oldest first."""

    frames: list[bytes] = Field(description="each width x height x 3 bytes (R, G, B), rows top first")
    more: bool = Field(description="more frames wait: call again")
    width: int = Field(ge=1)
    height: int = Field(ge=1)
    full: bool = Field(description="the movie reached its frame limit: no more frames are taken")
    failed: str = Field(description="why the server stopped taking frames, or empty")


class IntValue(Result):
    value: int


class FloatArrayValue(Result):
    value: list[float]


class BoolValue(Result):
    value: bool


class ContactPointsResult(Result):
    points: list[float] = Field(description="x, y, z (world, m) of each contact point, one after the other")
    nodes: list[int] = Field(description="for each point, the id of the Solid whose bounding shape touches there "
                             "(the node itself or, with include_descendants, a solid inside it)")


class DeviceListResult(Result):
    list: list[str]


class PoseResult(Result):
    translation: list[float]
    quaternion: list[float] = Field(description="x, y, z, w")


class LidarInfoResult(Result):
    horizontalResolution: int
    numberOfLayers: int
    fov: float
    verticalFov: float
    minRange: float
    maxRange: float


class FrequencyInfoResult(Result):
    frequency: float
    minFrequency: float
    maxFrequency: float


class StatusResult(Result):
    status: int


class RecognitionObject(Result):
    """One object a camera recognised (Webots' ``WbCameraRecognitionObject``)."""

    id: int = Field(description="the object's node id (Supervisor ids: robots 1..R, then top-level solids)")
    position: list[float] = Field(description="m: its box's centre in the camera frame (FLU)")
    orientation: list[float] = Field(description="axis-angle of its rotation in the camera frame")
    size: list[float] = Field(description="m: its box's extents along the camera's y and z")
    position_on_image: list[int] = Field(description="pixel: its box's centre on the image")
    size_on_image: list[int] = Field(description="pixels: width, height of its box on the image")
    colors: list[float] = Field(description="its recognition colours, flat [r0, g0, b0, r1, ...]")
    model: str


class RecognitionObjectsResult(Result):
    value: list[RecognitionObject]


class LayerRangeImageResult(Result):
    image: Image


class LayerPointCloudResult(Result):
    pointCloud: PointCloud


class StringValue(Result):
    value: str


class NodeResult(Result):
    node: int = Field(description="node id (0: the root); with type '' there is no such node (Webots' NULL)")
    type: str = Field(description="Webots' base type name: Group (the root), Robot, Solid, PointLight, SpotLight, "
                                  "DirectionalLight, a top-level node's not simulated (WorldInfo, Viewpoint, ...), "
                                  "or a nested node's (Solid, Pose, Camera, HingeJoint, ...); '' = no such node")
    proto: str = Field(default="", description="a PROTO instance: the PROTO's name (Webots' getTypeName; "
                                               "isProto); '' for a base node")
    name: str = Field(description="the node's name (a robot's or solid's name field; a light's world-file name)")
    def_name: str = Field(description="its DEF name ('' without one)")
    parent: int = Field(description="the parent's node id (0 for a top-level node, the robot's or solid's id (or a "
                                    "nested node's) for a nested node; -1 for the root and NULL)")


class ProtoDefResult(NodeResult):
    note: str = Field(default="", description="why there is no node to give, when Webots would print it or Sensorium "
                                              "departs from Webots ('node' is no PROTO instance, the DEF names a "
                                              "node Sensorium does not serve, ...); '' otherwise")


class FieldValueResult(Result):
    type: str = Field(description="Webots' field type name (SFVec3f, SFRotation, SFColor, SFFloat, SFInt32, SFBool, "
                                  "SFString, SFNode, MFNode, MFColor); '' = the node has no such field here (the value "
                                  "is then [])")
    value: bool | int | float | str | list[float] | list[int] | list[bool] | list[str] | list[list[float]] = Field(
        description="SFBool bool; SFFloat/SFInt32 number; SFString str; SFVec2f/SFVec3f/SFColor/SFRotation numbers; "
                    "SFNode the node's id; MFNode node ids; MFBool/MFInt32/MFFloat/MFString one item each; "
                    "MFVec2f/MFVec3f/MFColor/MFRotation one list of numbers per item (a PROTO's interface fields "
                    "have any of these types)")
    absent: bool = Field(default=False, description="with type '': Webots' node of this type has no such field "
                                                     "either (a Solid's endPoint, a motor's children): the clients "
                                                     "answer NULL silently, as libController does")
    note: str = Field(default="", description="a field whose value is not served (a PROTO's node-typed field that "
                                               "does not pass straight to a base-node field, a value over 4096 items): "
                                               "why, in one line; value is then [] and the clients print the line "
                                               "and answer Webots' no value when it is read")


class ProtoResult(Result):
    type_name: str = Field(description="the PROTO's name; '' = no such PROTO (a base node, a level past the chain: "
                                       "Webots' NULL)")
    derived: bool = Field(default=False, description="its body is an instance of another PROTO (getParent is that one)")
    fields: list[str] = Field(default=[], description="its interface fields' names in declaration order "
                                                      "(getNumberOfFields, getFieldByIndex)")


class NodePoseResult(Result):
    position: list[float] = Field(description="world x, y, z (m)")
    orientation: list[float] = Field(description="3x3 rotation matrix, row-major (Webots getOrientation)")


class CountersResult(Result):
    """``get_counters`` (debug): what the simulation computed so far and what is demanded."""

    time_ms: int
    steps: int
    counters: dict[str, int] = Field(description="the simulation's work counters (rays per device kind, points built, ...)")
    measurements: dict[str, int] = Field(description="values produced so far, per 'robot/device'")
    demanded: list[str] = Field(description="topics covered by a subscription or the recorder")
    subscriptions: list[bytes] = Field(description="active XPUB subscription prefixes")


class ServiceRef(Result):
    """One concrete service of the world, as ``get_services`` lists it."""

    name: str
    scope: Literal["server", "robot", "device"]
    robot: str | None = None
    device: str | None = None
    device_type: str | None = None
    attached: bool = Field(description="only the robot's attached controller may call it")
    supervisor: bool = Field(default=False, description="... and only if the robot has supervisor: true (Supervisor API)")
    simulated: bool = Field(default=True, description="false: a listed device's functions, answered by the client with Webots' 'no value'")
    args: dict[str, str] = Field(description="argument name -> type; a trailing '?' marks an optional one")


class ServicesResult(Result):
    services: list[ServiceRef]


def _type_text(t: Any) -> str:
    origin, params = get_origin(t), get_args(t)
    if origin is Literal:
        return "|".join(str(p) for p in params)
    if origin is Annotated:
        return _type_text(params[0])
    if origin in (Union, UnionType):
        return " | ".join(_type_text(p) for p in params if p is not type(None))
    if origin in (list, tuple):
        inner = [p for p in params if p is not Ellipsis]
        return "[" + ", ".join(_type_text(p) for p in inner) + (", ..." if origin is list or Ellipsis in params else "") + "]"
    if origin is dict:
        return "{" + f"{_type_text(params[0])}: {_type_text(params[1])}" + "}"
    if isinstance(t, type) and issubclass(t, BaseModel):
        return "{" + ", ".join(f"{k}: {v}" for k, v in arg_types(t).items()) + "}"
    return getattr(t, "__name__", str(t))


def arg_types(model: type[BaseModel]) -> dict[str, str]:
    """``{name: type}`` of an argument model for people (``get_services``, ``sensorium services``);
    a trailing ``?`` marks an optional argument."""
    return {name: _type_text(f.annotation) + ("" if f.is_required() else "?") for name, f in model.model_fields.items()}


# ---------------------------------------------------------------------- the table

@dataclass(frozen=True, slots=True)
class ServiceSpec:
    """One service: ``scope`` 'server' (name as is), 'robot' (``/<robot>/robot/<item>``) or
    'device' (``/<robot>/<device>/<item>``, offered by ``devices``); ``attached``: the caller must
    be the robot's attached controller."""

    item: str
    scope: Literal["server", "robot", "device"]
    args: type[Args]
    result: type[Result]
    attached: bool = False
    supervisor: bool = False       # the robot's world entry must have ``supervisor: true``

    @property
    def devices(self) -> frozenset[str]:
        """The device kinds that offer a device-scope service (their declarations in
        :mod:`sensorium.schemas.devices` list its item)."""
        if self.scope != "device":
            return frozenset()
        from sensorium.schemas.devices import KINDS  # devices.py imports world and messages only
        return frozenset(k.type for k in KINDS.values() if self.item in k.services)


SERVICES: tuple[ServiceSpec, ...] = (
    ServiceSpec("get_info", "server", NoArgs, InfoResult),
    ServiceSpec("attach", "server", AttachArgs, AttachResult),
    ServiceSpec("detach", "server", SessionArgs, Empty),
    ServiceSpec("ping", "server", SessionArgs, TimeResult),
    ServiceSpec("set_mode", "server", SetModeArgs, ModeResult),
    ServiceSpec("get_counters", "server", NoArgs, CountersResult),
    ServiceSpec("get_services", "server", NoArgs, ServicesResult),
    ServiceSpec("step", "robot", StepArgs, StepResult, attached=True),
    ServiceSpec("time_step", "robot", TimeStepArgs, SuccessResult, attached=True),
    ServiceSpec("get_time", "robot", NoArgs, FloatValue),
    ServiceSpec("get_basic_time_step", "robot", NoArgs, FloatValue),
    ServiceSpec("get_device_list", "robot", NoArgs, DeviceListResult),
    ServiceSpec("get_number_of_devices", "robot", NoArgs, IntValue),
    ServiceSpec("set_pose", "robot", SetPoseArgs, SuccessResult),
    ServiceSpec("get_pose", "robot", NoArgs, PoseResult),
    ServiceSpec("get_custom_data", "robot", NoArgs, StringValue),
    ServiceSpec("set_custom_data", "robot", StringArgs, SuccessResult, attached=True),
    ServiceSpec("get_model", "robot", NoArgs, StringValue),
    ServiceSpec("battery_sensor_enable", "robot", EnableArgs, SuccessResult, attached=True),
    ServiceSpec("battery_sensor_get_sampling_period", "robot", NoArgs, IntValue),
    ServiceSpec("battery_sensor_get_value", "robot", NoArgs, FloatValue),
    ServiceSpec("get_urdf", "robot", UrdfArgs, StringValue),
    ServiceSpec("wwi_send", "robot", WindowTextArgs, SuccessResult, attached=True),
    ServiceSpec("window_send", "robot", WindowTextArgs, WindowQueuedResult),
    ServiceSpec("get_from_def", "robot", NodeNameArgs, NodeResult, attached=True, supervisor=True),
    ServiceSpec("get_from_proto_def", "robot", ProtoDefArgs, ProtoDefResult, attached=True, supervisor=True),
    ServiceSpec("get_self", "robot", NoArgs, NodeResult, attached=True, supervisor=True),
    ServiceSpec("get_from_device", "robot", NodeDeviceArgs, NodeResult, attached=True, supervisor=True),
    ServiceSpec("get_root", "robot", NoArgs, NodeResult, attached=True, supervisor=True),
    ServiceSpec("get_from_id", "robot", NodeIdArgs, NodeResult, attached=True, supervisor=True),
    ServiceSpec("get_field", "robot", FieldArgs, FieldValueResult, attached=True, supervisor=True),
    ServiceSpec("set_field", "robot", SetFieldArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("get_proto", "robot", ProtoArgs, ProtoResult, attached=True, supervisor=True),
    ServiceSpec("get_actual_field", "robot", FieldArgs, StringValue, attached=True, supervisor=True),
    ServiceSpec("set_visibility", "robot", SetVisibilityArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("move_viewpoint", "robot", NodeArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("get_node_pose", "robot", NodeArgs, NodePoseResult, attached=True, supervisor=True),
    ServiceSpec("get_node_velocity", "robot", NodeArgs, FloatArrayValue, attached=True, supervisor=True),
    ServiceSpec("get_node_center_of_mass", "robot", NodeArgs, FloatArrayValue, attached=True, supervisor=True),
    ServiceSpec("get_node_static_balance", "robot", NodeArgs, BoolValue, attached=True, supervisor=True),
    ServiceSpec("get_node_contact_points", "robot", ContactPointsArgs, ContactPointsResult, attached=True,
                supervisor=True),
    ServiceSpec("remove_node", "robot", NodeArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("set_joint_position", "robot", SetJointPositionArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("save_node_state", "robot", NodeStateArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("load_node_state", "robot", NodeStateArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("import_node_from_string", "robot", ImportNodeArgs, IntArrayValue, attached=True, supervisor=True),
    ServiceSpec("simulation_reset", "robot", NoArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("reset_physics", "robot", NodeArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("restart_controller", "robot", NodeArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("world_reload", "robot", NoArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("world_load", "robot", WorldLoadArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("simulation_quit", "robot", SimulationQuitArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("simulation_set_mode", "robot", SimulationModeArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("simulation_get_mode", "robot", NoArgs, IntValue, attached=True, supervisor=True),
    ServiceSpec("set_label", "robot", SetLabelArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("export_image", "robot", NoArgs, ImageResult, attached=True, supervisor=True),
    ServiceSpec("movie_start", "robot", MovieStartArgs, MovieStartResult, attached=True, supervisor=True),
    ServiceSpec("movie_frames", "robot", NoArgs, MovieFramesResult, attached=True, supervisor=True),
    ServiceSpec("movie_stop", "robot", NoArgs, IntValue, attached=True, supervisor=True),
    ServiceSpec("node_export_string", "robot", NodeArgs, StringValue, attached=True, supervisor=True),
    ServiceSpec("world_save", "robot", NoArgs, StringValue, attached=True, supervisor=True),
    ServiceSpec("field_remove_sf", "robot", FieldArgs, SuccessResult, attached=True, supervisor=True),
    ServiceSpec("enable", "device", EnableArgs, SuccessResult, attached=True),
    ServiceSpec("get_sampling_period", "device", NoArgs, IntValue),
    ServiceSpec("get_lookup_table", "device", NoArgs, FloatArrayValue),
    ServiceSpec("get_min_value", "device", NoArgs, FloatValue),
    ServiceSpec("get_max_value", "device", NoArgs, FloatValue),
    ServiceSpec("get_aperture", "device", NoArgs, FloatValue),
    ServiceSpec("get_type", "device", NoArgs, IntValue),
    ServiceSpec("get_info", "device", NoArgs, LidarInfoResult),
    ServiceSpec("enable_point_cloud", "device", BoolArgs, SuccessResult, attached=True),
    ServiceSpec("is_point_cloud_enabled", "device", NoArgs, StatusResult),
    ServiceSpec("get_frequency_info", "device", NoArgs, FrequencyInfoResult),
    ServiceSpec("set_frequency", "device", FrequencyArgs, SuccessResult, attached=True),
    ServiceSpec("get_layer_range_image", "device", LayerArgs, LayerRangeImageResult),
    ServiceSpec("get_layer_point_cloud", "device", LayerArgs, LayerPointCloudResult),
    ServiceSpec("set_position", "device", MotorPositionArgs, SuccessResult, attached=True),
    ServiceSpec("set_velocity", "device", MotorVelocityArgs, SuccessResult, attached=True),
    ServiceSpec("get_velocity", "device", NoArgs, FloatValue),
    ServiceSpec("get_max_velocity", "device", NoArgs, FloatValue),
    ServiceSpec("get_target_position", "device", NoArgs, FloatValue),
    ServiceSpec("get_value", "device", NoArgs, FloatValue),
    ServiceSpec("set", "device", IntArgs, SuccessResult, attached=True),
    ServiceSpec("get", "device", NoArgs, IntValue),
    ServiceSpec("get_values", "device", NoArgs, FloatArrayValue),
    ServiceSpec("get_speed", "device", NoArgs, FloatValue),
    ServiceSpec("get_speed_vector", "device", NoArgs, FloatArrayValue),
    ServiceSpec("get_coordinate_system", "device", NoArgs, IntValue),
    ServiceSpec("get_roll_pitch_yaw", "device", NoArgs, FloatArrayValue),
    ServiceSpec("get_quaternion", "device", NoArgs, FloatArrayValue),
    ServiceSpec("get_noise", "device", NoArgs, FloatValue),
    ServiceSpec("write", "device", BoolArgs, SuccessResult, attached=True),
    ServiceSpec("set_ink_color", "device", InkColorArgs, SuccessResult, attached=True),
    ServiceSpec("draw", "device", DrawArgs, DrawResult, attached=True),
    ServiceSpec("set_exposure", "device", ExposureArgs, SuccessResult, attached=True),
    ServiceSpec("set_fov", "device", FovArgs, SuccessResult, attached=True),
    ServiceSpec("recognition_enable", "device", EnableArgs, SuccessResult, attached=True),
    ServiceSpec("get_recognition_sampling_period", "device", NoArgs, IntValue),
    ServiceSpec("enable_segmentation", "device", BoolArgs, SuccessResult, attached=True),
    ServiceSpec("is_segmentation_enabled", "device", NoArgs, StatusResult),
    ServiceSpec("get_recognition_objects", "device", NoArgs, RecognitionObjectsResult),
    ServiceSpec("get_channel", "device", NoArgs, IntValue),
    ServiceSpec("set_channel", "device", ChannelArgs, SuccessResult, attached=True),
    ServiceSpec("get_range", "device", NoArgs, FloatValue),
    ServiceSpec("set_range", "device", RangeArgs, SuccessResult, attached=True),
    ServiceSpec("get_buffer_size", "device", NoArgs, IntValue),
    ServiceSpec("get_targets", "device", NoArgs, FloatArrayValue),
    ServiceSpec("set_on", "device", BoolArgs, SuccessResult, attached=True),
    ServiceSpec("play_sound", "device", PlaySoundArgs, SuccessResult, attached=True),
    ServiceSpec("stop", "device", StringArgs, SuccessResult, attached=True),
    ServiceSpec("speak", "device", SpeakArgs, SuccessResult, attached=True),
    ServiceSpec("lock", "device", NoArgs, StatusResult, attached=True),
    ServiceSpec("unlock", "device", NoArgs, StatusResult, attached=True),
    ServiceSpec("is_locked", "device", NoArgs, StatusResult),
)


def spec(scope: str, item: str) -> ServiceSpec:
    for s in SERVICES:
        if s.scope == scope and s.item == item:
            return s
    raise KeyError(f"no {scope} service {item!r}")


def service_names(robots: dict[str, dict[str, str]]) -> dict[str, ServiceSpec]:
    """Every concrete service name of a world: ``robots`` maps robot → {device: device type}
    (motors included, type ``RotationalMotor``)."""
    out: dict[str, ServiceSpec] = {}
    for s in SERVICES:
        if s.scope == "server":
            out[s.item] = s
    for robot, devices in robots.items():
        for s in SERVICES:
            if s.scope == "robot":
                out[f"/{robot}/robot/{s.item}"] = s
        for dev, kind in devices.items():
            for s in SERVICES:
                if s.scope == "device" and kind in s.devices:
                    out[f"/{robot}/{dev}/{s.item}"] = s
    return out
