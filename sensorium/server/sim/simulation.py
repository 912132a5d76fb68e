"""In-process simulation: integer clock, due-device schedule, one batched ray cast per step.

    sim = Simulation.from_file("worlds/arena.yaml")
    ps0 = sim.device("epuck/ps0"); ps0.enable(32)
    sim.step(); print(ps0.value)

Each ``step()`` advances the clock by one basic time step (integer milliseconds, never a float
sum), applies pending pose changes, asks every *due* device for its rays at the end-of-step pose,
casts all of them in one call per ray kind, and lets each device reduce its hits to values.
Nothing is computed for a device that is disabled.
"""

from __future__ import annotations

import math
import warnings
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any, cast

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import light as light_math
from sensorium.server.raycast.engine import Mount, Precision, RayHits
from sensorium.server.sim.batches import DistanceBatch, DistancePlan, LightBatch, joined, split_hits
from sensorium.server.sim.battery import Battery, Charger
from sensorium.server.sim.belt import Belts
from sensorium.server.sim.cameras import Camera
from sensorium.server.sim.connector import Connector, SolidConnector, solid_connectors
from sensorium.server.sim.contact import Contact
from sensorium.server.sim.display import screen_image
from sensorium.server.sim.falling import Falls
from sensorium.server.sim.follow import ViewFollow
from sensorium.server.sim.ground import (
    Ground,
    GroundPieces,
    GroundWarning,
    band_low,
    land_solid,
    settle_pose,
    settle_world,
    settles,
)
from sensorium.server.sim.joints import JointMotor, Links
from sensorium.server.sim.motion import (
    _TO_ENU,
    AckermannDrive,
    DifferentialDrive,
    MecanumDrive,
    OmniDrive,
    SteeredDrive,
    WheelMotor,
)
from sensorium.server.sim.pen import Pen, lay_ink
from sensorium.server.sim.radar import Radar
from sensorium.server.sim.radio import Emitter, Radio, Receiver
from sensorium.server.sim.scene import (
    Scene,
    charger_glow,
    light_from_model,
    primitive_from_model,
    robot_bounding_parts,
    robot_parts,
    solid_lights,
    solid_parts,
    solid_radar_targets,
)
from sensorium.server.sim.sensors import (
    GPS,
    LED,
    Device,
    DistanceSensor,
    Lidar,
    LightSensor,
    RayRequest,
    Schedule,
    TouchSensor,
    device_class,
)
from sensorium.server.sim.speaker import Speaker
from sensorium.server.sim.vacuum import VacuumGripper, caught_at_load
from sensorium.server.world.geometry import Pose
from sensorium.server.world.limits import WorldLimits, check_pose
from sensorium.server.world.loader import LoadedWorld, from_model, load_world
from sensorium.server.world.poses import moved_pose, pose_from_model
from sensorium.server.world.report import warn_losses
from sensorium.server.world.top_nodes import top_level

# the devices that cast rays into the scene: what may see a Display's screen (its texels' colours, or its alpha
# letting rays and shadows through); while none is enabled a screen is not retextured (Simulation.show_screens)
SCREEN_WATCHERS = frozenset({"Camera", "RangeFinder", "DistanceSensor", "LightSensor", "Lidar", "Radar", "Receiver"})


@dataclass(slots=True)
class Rider:
    """A robot riding another, fixed in its frame (``carried_by``): its frame there now and as loaded."""

    robot: RobotState
    carrier: RobotState
    frame: Pose
    parent: Pose | None = None      # its parent's frame in the carrier's (Poses between), where its fields are
    loaded_frame: Pose = field(init=False)

    def __post_init__(self) -> None:
        self.loaded_frame = self.frame


_REMOVED = wm.Solid.model_construct(name="", def_name="")   # a removed imported solid's model: its name and DEF
_NOBODY: frozenset[int] = frozenset()   # no robot powered off (a world without batteries)


class SettlingGrounds:
    """Where a robot a Supervisor puts at a pose settles, for ``Simulation.settled`` and each copy of
    the batched simulation alike: a wheeled robot that settles at load (its drive gives
    ``wheel_bottom``) settles there on the ground as the world is now -- the solids where they are,
    the robots without a drive (``floors``: (model, pose) each) where they are -- with settle_world's
    arithmetic (ground.settle_pose); any other robot keeps its pose. The ground is built once for
    what it is made of (the scene's solids' and shapes' versions, the floors' poses), at most
    ``size`` of them kept (one per batched copy), from each solid's and floor's pieces kept while it stays
    as it is (ground.GroundPieces)."""

    def __init__(self, to_enu: np.ndarray | None, size: int = 1):
        self.to_enu = to_enu
        self.size = size
        self._grounds: dict[tuple, Ground | None] = {}
        self._pieces = GroundPieces(to_enu)

    def settled(self, model: wm.Robot, pose: Pose, solids: list[wm.Solid], scene: Scene,
                floors: Callable[[], list[tuple[wm.Robot, Pose]]]) -> Pose:
        if not settles(model):
            return pose
        under = floors()
        key = (scene.solids_version, scene.shapes_version,
               *(p.translation.tobytes() + p.rotation.tobytes() for _, p in under))
        if key not in self._grounds:
            if len(self._grounds) >= self.size:
                self._grounds.clear()
            alive = scene.solid_poses
            # of the pieces kept (ground.GroundPieces): a solid's made again only once it changed, so a move
            # after a solid's (an RL reset) does not read every solid again; settling_ground's ground, bit for bit
            self._grounds[key] = self._pieces.ground([(s, alive[s.name]) for s in solids if s.name in alive],
                                                     [(r, p, (r,), partial(robot_parts, r)) for r, p in under])
        return settle_pose(model, pose, self._grounds[key], self.to_enu)


def lights_from_models(models: list) -> light_math.LightArrays:
    """The lights that are on, as arrays in world coordinates (lights that are off contribute nothing)."""
    return light_math.LightArrays.from_lights([light_from_model(m) for m in models if m.on])


@dataclass(frozen=True, slots=True)
class DeviceEntry:
    """One device of a robot as Webots lists it (``wb_robot_get_device_by_index``): its index in
    the robot's tree order (the world file's ``devices`` order, then the drive's motors that the
    list leaves out), Webots node type, name, ``model`` field, and whether Sensorium simulates it."""

    index: int
    type: str
    name: str
    model: str
    simulated: bool


def device_entries(model: wm.Robot, devices: dict[str, Device],
                   motors: dict[str, WheelMotor | JointMotor]) -> list[DeviceEntry]:
    out: list[DeviceEntry] = []
    for d in model.devices:
        simulated = d.name in (motors if isinstance(d, wm.Motor) else devices)
        out.append(DeviceEntry(len(out), d.device, d.name, getattr(d, "model", "") or "", simulated))
    listed = {e.name for e in out}
    for name in motors:
        if name not in listed:
            out.append(DeviceEntry(len(out), "RotationalMotor", name, "", True))
    return out


def joint_motor(d: wm.RotationalMotor | wm.LinearMotor) -> JointMotor:
    """The kinematic joint a motor entry that is no drive motor moves."""
    force = d.max_torque if isinstance(d, wm.RotationalMotor) else d.max_force
    return JointMotor(d.name, d.device, d.max_velocity, d.min_position, d.max_position, d.acceleration, force,
                      d.position, multiplier=d.multiplier)


def couple(joints: dict[str, JointMotor]) -> None:
    """Webots' coupled motors among a robot's joint motors: those whose names share the part before
    ``::`` (wm.coupling_group) each hold the others, to pass on the commands they take."""
    groups: dict[str, list[JointMotor]] = {}
    for name, motor in joints.items():
        group = wm.coupling_group(name)
        if group is not None:
            groups.setdefault(group, []).append(motor)
    for members in groups.values():
        for motor in members:
            motor.coupled = tuple(m for m in members if m is not motor)


class RobotState:
    """A robot: its devices by name and its pose."""

    def __init__(self, sim: Simulation, index: int, model: wm.Robot):
        self._sim = sim
        self.index = index
        self.model = model
        self.name = model.name
        self.synchronization = model.synchronization
        self.controller = model.controller
        self.devices: dict[str, Device] = {}
        for d in model.devices:
            cls = device_class(d.device)
            if cls is None or not issubclass(cls, Device):   # listed only, or a motor (the drive owns wheels)
                continue
            self.devices[d.name] = cls(config=d, robot_index=index, robot_name=model.name,
                                       self_collision=model.self_collision, world_seed=sim.seed,
                                       clock=lambda: sim.time_ms, own_shapes=sim.scene.device_shapes(index, d.name))
        up = sim.world.world_info.coordinate_system
        self.initial_pose = sim.scene.robot_poses[index]     # as the world file places it (reset puts it back there)
        self.drive: DifferentialDrive | AckermannDrive | MecanumDrive | OmniDrive | SteeredDrive | None = None
        low = sim.band_low(index) if sim.ground is not None else 0.0     # (its support ceiling: sim/ground.py)
        if model.differential_drive is not None:
            # a robot without Physics (Webots' kinematic rule, mid_heading) moves in its plane only: Webots
            # gives it no contact with the ground, so it rides no terrain or ramp and keeps its height and tilt
            kinematic = model.differential_drive.step_rule == "mid_heading"
            self.drive = DifferentialDrive(model.differential_drive, sim.scene.robot_poses[index], up=up,
                                           ground=None if kinematic else sim.ground, band_low=0.0 if kinematic else low)
        elif model.ackermann_drive is not None:
            self.drive = AckermannDrive(model.ackermann_drive, sim.scene.robot_poses[index], up=up, ground=sim.ground,
                                        band_low=low)
        elif model.mecanum_drive is not None:
            self.drive = MecanumDrive(model.mecanum_drive, sim.scene.robot_poses[index], up=up, ground=sim.ground,
                                      band_low=low)
        elif model.omni_drive is not None:
            self.drive = OmniDrive(model.omni_drive, sim.scene.robot_poses[index], up=up, ground=sim.ground,
                                   band_low=low)
        elif model.steered_drive is not None:
            self.drive = SteeredDrive(model.steered_drive, sim.scene.robot_poses[index], up=up, ground=sim.ground,
                                      band_low=low)
        if self.drive is not None and self.drive.slope is not None:   # placed on a slope: its attitude
            sim.scene.set_robot_pose(index, self.drive.pose())
        drive_motors: dict[str, WheelMotor] = self.drive.motors if self.drive else {}
        # every other motor moves its joint kinematically (sim/joints.py), in device-list order
        self.joints: dict[str, JointMotor] = {d.name: joint_motor(d) for d in model.devices
                                              if isinstance(d, wm.Motor) and d.name not in drive_motors}
        couple(self.joints)
        if isinstance(self.drive, SteeredDrive):     # its wheels' headings are its steering joints' positions
            self.drive.bind(self.joints)
        self.motors: dict[str, WheelMotor | JointMotor] = (
            {**drive_motors, **self.joints} if self.joints else cast("dict[str, WheelMotor | JointMotor]", drive_motors))
        # what rides on the joints (``on_joint``): their links, and the devices on each (None: nothing rides)
        self.links: Links | None = None
        self.riders: dict[str, list[Device]] = {}
        if any(getattr(x, "on_joint", None) is not None for x in (*model.shapes, *model.devices, *model.lights)):
            self.links = Links(model, self.joints)
            for dev in self.devices.values():
                if dev.on_joint is not None:
                    self.riders.setdefault(dev.on_joint, []).append(dev)
                    dev.link_body = sim.scene.device_body(index, dev.on_joint)
                    dev.move_with(self.links.poses[dev.on_joint])
        # the joints carrying bounding shapes: kinematic contact's footprint (and a bumper's pieces)
        # follow them, made again only on a step one of them moved (move_links)
        self._bound_joints = frozenset(shape.on_joint for shape in model.shapes
                                       if shape.on_joint is not None and shape.seen_by in ("both", "bounding"))
        self._bounding: list[tuple[Any, Pose, str | None]] | None = None     # made when first asked for
        for dev in self.devices.values():
            dev.bind(self)
        self.device_list = device_entries(model, self.devices, self.motors)
        self.pressing = False         # kinematic contact clipped the drive's motion in the last step
        self.custom_data = model.custom_data
        self.supervisor = model.supervisor
        self.battery = Battery.from_model(model)
        self.battery_schedule = Schedule()      # its battery sensor (Webots' wb_robot_battery_sensor_*)
        self.battery_value = math.nan           # the sensor's latest value (J)
        # its /<robot>/battery topic (daemon/topics.py): demanded, it samples at every basic step unless the
        # controller's sensor samples; each sample keeps (energy J, maximum J, Battery.state) and its time
        self.battery_demanded = False
        self.battery_samples = 0
        self.battery_sampled_at_ms = 0
        self.battery_sample: tuple[float, float, str] = (math.nan, math.nan, "idle")

    @property
    def pose(self) -> Pose:
        return self._sim.scene.robot_poses[self.index]

    @property
    def world_info(self) -> wm.WorldInfo:
        return self._sim.world.world_info

    @property
    def scene(self) -> Scene:
        """The world's scene (devices that cast their own rays, e.g. cameras, bind to it)."""
        return self._sim.scene

    @property
    def basic_time_step(self) -> int:
        return self._sim.basic_time_step

    @property
    def simulation(self) -> Simulation:
        """The simulation the robot is in (a VacuumGripper reads the other solids and robots from it)."""
        return self._sim

    @property
    def to_enu(self) -> np.ndarray | None:
        """The world's axes to ENU (None in an ENU world), as kinematic contact takes them."""
        return _TO_ENU[self._sim.world.world_info.coordinate_system]

    def move_links(self) -> bool:
        """The joints moved: their links' bodies and the devices on them follow (whether a device moved)."""
        if self.links is None:
            return False
        moved = False
        changed = self.links.update()
        for joint in changed:
            displacement = self.links.poses[joint]
            self._sim.scene.set_link_pose(self.index, joint, displacement)
            for dev in self.riders.get(joint, ()):
                dev.move_with(displacement)
                moved = True
        if changed and self._bound_joints and not self._bound_joints.isdisjoint(changed):
            contact = self._sim.contact
            if contact is not None:      # its footprint where the joints hold its shapes now
                contact.reshape(self.index, self.bounding_parts())
        return moved

    def bounding_parts(self) -> list[tuple[Any, Pose]]:
        """The robot's bounding shapes (primitive, pose in the robot frame) where its joints hold
        them now: :func:`~sensorium.server.sim.scene.robot_bounding_parts` (the same order), each
        shape on a joint (``on_joint``) moved by its link's displacement."""
        if self._bounding is None:
            base = self._sim.loaded.base_dir
            self._bounding = [(primitive_from_model(shape.geometry, base), local, getattr(shape, "on_joint", None))
                              for _, local, shape in robot_parts(self.model) if shape.seen_by in ("both", "bounding")]
        poses = self.links.poses if self.links is not None else {}
        return [(prim, local if joint is None or joint not in poses else poses[joint].compose(local))
                for prim, local, joint in self._bounding]

    def link_pose(self, joint: str) -> Pose | None:
        """The displacement (robot frame) of what rides on ``joint`` from its world-file place now
        (None: nothing rides on it, or it is no joint that moves)."""
        return None if self.links is None else self.links.poses.get(joint)

    def set_pose(self, translation=None, rotation=None, quaternion=None) -> None:
        """Move the robot (supervisor-style, kinematically, no contact check — as Webots' field
        setters); the next measurement sees it there. Translation and rotation are independent
        (Webots): leave one out (``None``) and it keeps its current value. Non-finite values or a
        translation beyond ``limits.MAX_COORDINATE_M`` raise ValueError and the robot stays.
        A wheeled robot that settled at load settles again where it is put (Simulation.settled: its
        lowest wheel on the ground under its origin, at once, where Webots' physics would drop it).
        A driven robot set over a terrain rides it from there (sim/ground.py): the height given is
        its clearance, the rotation its own (upright) one, the ground's attitude applied over it."""
        check_pose(translation, rotation, quaternion)
        current = self.drive.own_pose() if self.drive is not None and self.drive.slope is not None else self.pose
        pose = self._sim.settled(self.model, moved_pose(current, translation, rotation, quaternion))
        if self.drive is not None:
            self.drive.reset(pose)
            pose = self.drive.placed(pose)
        self._sim.place_robot(self, pose)
        self._sim.rider_moved(self)

    def motor(self, name: str) -> WheelMotor | JointMotor:
        try:
            return self.motors[name]
        except KeyError:
            raise KeyError(f"robot {self.name!r} has no motor {name!r} (motors: {', '.join(self.motors) or 'none'})") from None

    def device(self, name: str) -> Device:
        try:
            return self.devices[name]
        except KeyError:
            raise KeyError(f"robot {self.name!r} has no device {name!r} (devices: {', '.join(self.devices)})") from None


@dataclass
class StepReport:
    time_ms: int
    measured: list[Device]


class Simulation:
    def __init__(self, world: LoadedWorld | wm.World, precision: Precision | str = Precision.EXACT,
                 base_dir: Path | None = None, contact: bool | None = None, *, limits: WorldLimits | None = None,
                 allow_outside_meshes: bool = False):
        """``contact``: kinematic contact on/off (default: the world's ``world_info.contact``);
        ``limits``/``allow_outside_meshes``: what a Supervisor's imported nodes may add (the world's
        load settings; default ``WorldLimits()``)."""
        loaded = from_model(world, base_dir) if isinstance(world, wm.World) else world
        self.loaded = loaded
        # solids and lists of its own: a Supervisor's imports append to them (the loaded world stays as read)
        self.world = loaded.world.model_copy(update={"solids": list(loaded.world.solids),
                                                    "lights": list(loaded.world.lights)})
        # solids with physics and wheeled robots placed above (or into) the ground settle on it, as Webots'
        # physics drops them (sim/ground.py); the load report says which moved (the note once, however many
        # simulations)
        # (a solid a VacuumGripper on at load touches is held from the first step: it stays)
        to_enu = _TO_ENU[self.world.world_info.coordinate_system]
        self.world, settled = settle_world(self.world, to_enu, loaded.source, loaded.base_dir,
                                           caught_at_load(self.world, loaded.base_dir, to_enu))
        loaded.warnings.extend(note for note in settled if note not in loaded.warnings)
        self.limits = limits or WorldLimits()
        self.allow_outside_meshes = allow_outside_meshes
        self.imported: list[tuple[str, str | int]] = []     # (node type, key) of each node a Supervisor imported
        self.imported_protos: dict[str | int, str] = {}       # key -> the PROTO an imported node is an instance of
        self.imported_visuals: dict[str | int, Any] = {}      # key -> an imported Shape or Group (parsed; its solid's key)
        self.imported_interfaces: dict[str | int, tuple] = {}  # key -> that PROTO instance's interface fields
        self.imported_written: dict[str | int, Any] = {}      # key -> an imported node as written (parsed)
        self.top_level = top_level(self.world)     # the root's children as loaded (world/top_nodes.py)
        # the shapes a Supervisor hid from the Viewpoint (setVisibility), by the node hidden: viewshot's pictures
        self.viewpoint_hidden: dict[int, frozenset[int]] = {}
        # the Viewpoint's fields as loaded, kept when a Supervisor's moveViewpoint first moves it (reset restores them)
        self.viewpoint_loaded: dict | None = None
        self.viewpoint_follow: ViewFollow | None = None     # set once the scene is built (sim/follow.py)
        self.root_order: list[int] | None = None            # the Supervisor's order of the root's children once
                                                            # a node was imported (None: the loaded order)
        self._import_protos: Any = None                     # the world's EXTERNPROTO declarations, read once
        self._name_suffixes: dict[str, int] = {}            # imports' renames so far (imports.py _Converter)
        self._sizes: dict[str, int] | None = None           # see _solid_sizes
        self.basic_time_step = self.world.world_info.basic_time_step
        self.seed = self.world.world_info.random_seed
        self.time_ms = 0
        self.step_count = 0
        self.scene = Scene(self.world, loaded.base_dir, precision, images=dict(loaded.textures))

        def note(text: str) -> None:        # once however many simulations of the world
            line = f"{loaded.source}: {text}"
            if line not in loaded.warnings:
                loaded.warnings.append(line)

        self.viewpoint_follow = ViewFollow.of(self, note)
        self.ground = Ground.from_world(self.world, self.scene.solid_poses, _TO_ENU[self.world.world_info.coordinate_system])
        self.lights = lights_from_models(self.scene.sensor_lights())
        self._lights_version = self.scene.lights_version
        self.robots: dict[str, RobotState] = {r.name: RobotState(self, i, r) for i, r in enumerate(self.world.robots)}
        self._driven = [r for r in self.robots.values() if r.drive is not None]
        self._batteries = [r.battery for r in self.robots.values()]
        self._powered = [r for r in self.robots.values() if r.battery.present]
        self.chargers = [c for c in map(Charger.from_model, self.world.chargers) if c is not None]
        # each Charger's glowing shapes (those of charger_glow with an appearance) and their own colours, and its
        # glowing lights (their places among its solid's lights) and their own colours
        self._glowing: list[tuple[Charger, list[tuple[int, tuple]], list[tuple[int, tuple]]]] = []
        solids = {s.name: s for s in self.world.solids}
        for c in self.chargers:
            solid = solids.get(c.solid)
            shapes, lights = charger_glow(solid, c.glow_shapes, c.glow_lights, c.glow_solids) if solid else ([], [])
            mine = self.scene.solid_shapes(c.solid)
            slots = self.scene.solid_light_slots(c.solid)
            self._glowing.append((c, [(mine[i], self.scene.loaded_model(mine[i]).appearance.emissive_color)  # type: ignore[union-attr]
                                      for i in shapes if i < len(mine) and self.scene.loaded_model(mine[i]).appearance],
                                  [(i, tuple(self.scene.light_model(slots[i]).color)) for i in lights if i < len(slots)]))
        self._battery_sensing: list[RobotState] = []     # robots whose battery sensor is enabled or topic demanded
        self._jointed = [j for r in self.robots.values() for j in r.joints.values()]
        self._joint_robot = [r.index for r in self.robots.values() for _ in r.joints.values()]
        self._linked = [r for r in self.robots.values() if r.links is not None]
        if self.ground is not None:
            self._warn_ground()
        self._pens = [d for d in self.all_devices() if isinstance(d, Pen)]
        self._screens = self._display_screens()
        # what may see a screen (its colours, its alpha's see-through and shadows): shown only while one is enabled
        self._screen_watchers = [d for d in self.all_devices() if d.kind in SCREEN_WATCHERS] if self._screens else []
        self._speakers = [d for d in self.all_devices() if isinstance(d, Speaker)]
        self._grippers = [d for d in self.all_devices() if isinstance(d, VacuumGripper)]
        connectors = [d for d in self.all_devices() if isinstance(d, Connector)]
        peers: list[Connector | SolidConnector] = [*connectors, *solid_connectors(self.world.solids, self.scene)]
        for con in connectors:        # a connector's presence looks at every other one of the world
            con.peers = peers
        self._auto_locking = [c for c in connectors if c.config.auto_lock and c.config.type != "passive"]
        self._counters: Counter[str] = Counter()
        self._by_kind: tuple[list[LightSensor], list[DistanceSensor], list[Lidar], list[Device]] | None = None
        self._capturing: list[Any] = []     # devices that cast their own rays (cameras, range finders)
        self._tracking: list[Device] = []
        self._bumpers: list[TouchSensor] = []      # bumpers (TouchSensors of type bumper), sorted out with _by_kind
        self._distance_plans: dict[tuple[int, ...], DistancePlan] = {}   # by the due sensors (see _distance_plan)
        self._joined_mounts: dict[tuple, tuple[list, Mount]] = {}        # see _joined_mount
        use_contact = self.world.world_info.contact if contact is None else bool(contact)
        # a robot none drives has no contact to ask, unless a bumper of it may touch its own parts (selfCollision)
        pressed_by_own = any(isinstance(d, TouchSensor) and d.self_touching for d in self.all_devices())
        self.contact: Contact | None = self._build_contact() if use_contact and (self._driven or pressed_by_own) \
            else None
        every = list(self.all_devices())
        self.radio = Radio([d for d in every if isinstance(d, Emitter)], [d for d in every if isinstance(d, Receiver)],
                           self.scene, self._counters)
        # robots riding others (a .wbt Robot nested in another's children): each follows its carrier's pose,
        # fixed in its frame, from the carrier's settled pose at load on
        self._riders = [Rider(r, self.robots[r.model.carried_by.robot], pose_from_model(r.model.carried_by.frame),
                              None if r.model.carried_by.parent is None else pose_from_model(r.model.carried_by.parent))
                        for r in self.robots.values() if r.model.carried_by is not None]
        for ride in self._riders:
            if ride.robot.drive is not None:
                raise ValueError(f"robot {ride.robot.name!r}: a robot riding another has no drive of its own")
        # solids a Supervisor imported into a robot's children: each fixed in its robot's frame (ride_solid)
        self.solid_riders: dict[str, tuple[RobotState, Pose]] = {}
        if self.contact is not None and self._riders:     # one body with its carrier: never each other's obstacle
            carriers = {ride.carrier.index: [ride.carrier.index] for ride in self._riders}
            for ride in self._riders:
                carriers[ride.carrier.index].append(ride.robot.index)
            self.contact.attach(list(carriers.values()))
            for ride in self._riders:
                self._fix_rider(ride)
        self._carry()
        for ride in self._riders:
            ride.robot.initial_pose = ride.robot.pose
        self._initial: dict[str, Any] = {"robots": [(r.initial_pose, r.custom_data) for r in self.robots.values()],
                         "solids": dict(self.scene.solid_poses), "lights": self.scene.top_lights(),
                         "radar_targets": dict(self.scene.radar_targets)}
        self._imported_poses: dict[str, Pose] = {}      # each imported solid's pose as imported
        self._settling = SettlingGrounds(_TO_ENU[self.world.world_info.coordinate_system])
        self._pieces = GroundPieces(_TO_ENU[self.world.world_info.coordinate_system])    # landing_ground's
        # conveyor belts (sim/belt.py): none in most worlds, which then pay nothing for them
        self._belts = Belts(self, _TO_ENU[self.world.world_info.coordinate_system]) \
            if any(r.belts for r in self.world.robots) else None
        # solids a VacuumGripper let go, falling under gravity (sim/falling.py): none, no work
        self.falls = Falls(self, _TO_ENU[self.world.world_info.coordinate_system], self.world.world_info.gravity)

    def _warn_ground(self) -> None:
        """One GroundWarning per thing a driven robot will not ride on: a tilted terrain, a robot
        that starts over no ground (it keeps its height: terrains never lift it)."""
        assert self.ground is not None
        for name in self.ground.tilted_terrains():
            warnings.warn(f"{self.loaded.source}: solid {name!r}: its ElevationGrid is tilted (its local z is not "
                          "the world's up): not ground, robots keep their height over it", GroundWarning, stacklevel=3)
        for r in self._driven:
            if r.drive is not None and r.drive.ground is not None and r.drive.rest is None:   # (without Physics: none)
                warnings.warn(f"{self.loaded.source}: robot {r.name!r} starts over no ground (no upright terrain, "
                              "floor plane or box top at most 1 mm above its body's bottom under its origin): "
                              "it keeps its height, terrains do not lift it",
                              GroundWarning, stacklevel=3)

    def band_low(self, index: int) -> float:
        """Robot ``index``'s band bottom below its origin, as contact takes it (ground.band_low)."""
        return band_low(robot_bounding_parts(self.world.robots[index], self.loaded.base_dir),
                        self.scene.robot_poses[index], _TO_ENU[self.world.world_info.coordinate_system])

    def _build_contact(self) -> Contact:
        base = self.loaded.base_dir
        solids = [(s.name, primitive_from_model(shape.geometry, base), local, self.scene.solid_poses[s.name],
                   shape.seen_by in ("both", "bounding"))
                  for s in self.world.solids for _, local, shape in solid_parts(s, Pose.identity())]
        # each robot at its world-file pose: its footprint is taken upright (enu_body), not tilted by
        # the slope it may start on (the batched simulation's feet, from the same poses)
        robots = [(robot_bounding_parts(r, base), self.robots[r.name].initial_pose) for r in self.world.robots]
        # each robot's heading as its drive keeps it (its footprint is turned to it: contact.drive_footprint)
        yaws = [None if (d := self.robots[r.name].drive) is None else d.yaw for r in self.world.robots]
        return Contact(solids, robots, _TO_ENU[self.world.world_info.coordinate_system], yaws)

    def settled(self, model: wm.Robot, pose: Pose) -> Pose:
        """The pose a robot a Supervisor puts at ``pose`` takes (:class:`SettlingGrounds`): the
        robots without a drive where they are now."""
        return self._settling.settled(model, pose, self.world.solids, self.scene, lambda: [
            (r.model, self.scene.robot_poses[r.index]) for r in self.robots.values() if not r.model.drive_motors])

    def landing_ground(self, solid: str, carrier: int | None = None) -> Ground | None:
        """The ground a solid let go lands on (ground.land_solid): ground.settling_ground as the world is
        now, the other top-level solids where they are, the robots without a drive where they are with
        their shapes where their joints hold them (a lift's cup that just let go of a parcel is above it),
        a solid still falling where it will rest (sim/falling.py: a box let go over a falling one lands on it).
        ``carrier``: a robot (index) left out, the one holding the solid (one body with it)."""
        def parts(r: RobotState) -> list:
            return [(name, local if r.links is None or (j := getattr(shape, "on_joint", None)) not in r.links.poses
                     else r.links.poses[j].compose(local), shape) for name, local, shape in robot_parts(r.model)]

        floors = [(r.model, self.scene.robot_poses[r.index],
                   (r.model, *(() if r.links is None else r.links.poses.values())), partial(parts, r))
                  for r in self.robots.values() if not r.model.drive_motors and r.index != carrier]
        alive = self.scene.solid_poses
        resting = self.falls.resting           # a solid still falling is taken where it will rest
        # the pieces of each solid and robot kept while it stays as it is (ground.GroundPieces): the ground
        # settling_ground would build, bit for bit
        return self._pieces.ground([(s, resting(s.name, alive[s.name])) for s in self.world.solids
                                    if s.name in alive and s.name != solid], floors)

    def place_robot(self, robot: RobotState, pose: Pose) -> None:
        """Put a robot somewhere from outside (no contact check). Its gyros and accelerometers see a
        jump, not motion: their poses start over from there (_MotionSensor.placed); the robots riding
        it go with it."""
        self.scene.set_robot_pose(robot.index, pose)
        if self.contact is not None:
            self.contact.place(robot.index, pose, None if robot.drive is None else robot.drive.yaw)
        for dev in robot.devices.values():
            if dev.tracks_motion:
                dev.placed()          # type: ignore[attr-defined]
        for ride in self._riders:
            if ride.carrier is robot:
                self.place_robot(ride.robot, robot.pose.compose(ride.frame))

    def _carry(self) -> None:
        """The robots riding others where their carriers now put them (as they moved)."""
        for ride in self._riders:
            pose = ride.carrier.pose.compose(ride.frame)
            self.scene.set_robot_pose(ride.robot.index, pose)
            if self.contact is not None:          # other robots meet it where it is now
                self.contact.place(ride.robot.index, pose)

    def _fix_rider(self, ride: Rider) -> None:
        """A rider's shapes as loaded, at its frame, part of its carrier's outline for contact."""
        assert self.contact is not None
        parts = [(prim, ride.frame.compose(local)) for prim, local in
                 robot_bounding_parts(ride.robot.model, self.loaded.base_dir)]
        self.contact.fix_rider(ride.carrier.index, ride.robot.index, parts)

    def rider_frame(self, robot: RobotState, loaded: bool = False) -> Pose | None:
        """A robot riding another: its frame in its carrier's now (``loaded``: as the world file put it), its
        translation and rotation fields as Webots gives a nested node's, in its parent's frame; None for a
        robot that rides none."""
        ride = next((ride for ride in self._riders if ride.robot is robot), None)
        return None if ride is None else ride.loaded_frame if loaded else ride.frame

    def rider_parent(self, robot: RobotState) -> Pose | None:
        """A riding robot's parent's frame in its carrier's (the Poses between them), where its translation and
        rotation fields are; None when its parent is the carrier."""
        return next((ride.parent for ride in self._riders if ride.robot is robot), None)

    def riders_of(self, carrier: RobotState) -> list[RobotState]:
        """The robots riding ``carrier``, in world-file order."""
        return [ride.robot for ride in self._riders if ride.carrier is carrier]

    def rider_moved(self, robot: RobotState) -> None:
        """A robot riding another was put somewhere in the world (set_pose): it stays fixed to its carrier
        there, its frame on it where that puts it (carried from the next step, as Webots keeps a moved
        child in its parent)."""
        ride = next((ride for ride in self._riders if ride.robot is robot), None)
        if ride is not None:
            self.set_rider_frame(robot, ride.carrier.pose.inverse().compose(robot.pose))

    def set_rider_frame(self, robot: RobotState, frame: Pose) -> None:
        """A riding robot put elsewhere on its carrier (a Supervisor set its translation or rotation): fixed
        there from now on, where a reset puts it back as loaded."""
        ride = next(ride for ride in self._riders if ride.robot is robot)
        ride.frame = frame
        if self.contact is not None:
            self._fix_rider(ride)
        self.place_robot(robot, ride.carrier.pose.compose(frame))

    def reset(self) -> None:
        """Webots' ``simulationReset`` subset: robots and solids back to their initial poses, nodes a
        Supervisor imported removed (removed ones stay removed), wheel
        motors to their initial commands and angles, joints to their initial positions, top-level lights' fields as loaded, LEDs off, displays black (no image kept, no camera), pen ink cleared (the pens keep their
        ``write`` and ink, as Webots' WbPen::reset), custom data, batteries and Chargers' energies (Chargers idle), radar cross sections, vacuum grippers' pumps (nothing held) and connectors' lock states as in the world file, speakers silent, GPS and Radar speeds
        NaN at their next value (no previous position, as Webots' WbGps::reset and WbRadar::reset).
        The clock keeps running (the lockstep's time never goes back) and devices keep their
        sampling periods and last values."""
        for charger in self.chargers:
            charger.reset()
        for robot, (pose, data) in zip(self.robots.values(), self._initial["robots"]):
            robot.custom_data = data
            robot.battery.reset()
            loaded = Battery.from_model(robot.model)     # what a Supervisor wrote: as loaded
            robot.battery.maximum, robot.battery.speed, robot.battery.cpu = loaded.maximum, loaded.speed, loaded.cpu
            if robot.drive is not None:
                for m in robot.drive.motors.values():
                    m.target_position, m.velocity, m.position = 0.0, m.max_velocity, 0.0
                if isinstance(robot.drive, AckermannDrive):     # free wheels back at their world-file angles
                    robot.drive.free_turned = dict.fromkeys(robot.drive.free, 0.0)
                elif isinstance(robot.drive, SteeredDrive):
                    robot.drive.free_turned = dict.fromkeys(robot.drive.free_turned, 0.0)
                robot.drive.reset(pose)
                pose = robot.drive.placed(pose)
            for joint in robot.joints.values():
                joint.reset()
            self.joints_moved(robot)
            self.place_robot(robot, pose)
            for dev in robot.devices.values():
                if isinstance(dev, LED) and (dev.value != 0 or dev.dark):
                    dev.set(0, self.time_ms)
                elif isinstance(dev, (GPS, Radar)):      # no previous position: the next speeds are NaN
                    dev.restart()
                elif isinstance(dev, Connector):    # WbConnector::reset: the world file's lock state
                    dev.reset()
                elif dev.kind == "Display":      # WbDisplay::reset: black again, its images gone
                    dev.reset()               # type: ignore[attr-defined]
                    dev._mark(self.time_ms)
                elif isinstance(dev, (VacuumGripper, Speaker)):    # the pump as loaded; silence
                    dev.reset()
                elif isinstance(dev, Camera):      # a zoomed camera: the world file's fieldOfView
                    dev.reset_fov()
        self.radio.reset()
        self.falls.clear()
        for ride in self._riders:        # each rider where the world file put it on its carrier
            if ride.frame is not ride.loaded_frame:
                self.set_rider_frame(ride.robot, ride.loaded_frame)
        for name, pose in self._initial["solids"].items():
            if name not in self.scene.solid_poses:      # removed: stays removed (Webots' reset)
                continue
            self.place_solid(name, pose)
        for kind, key in self.imported:         # Webots' reset removes the nodes a Supervisor imported
            if kind == "Solid" and key in self.scene.solid_poses:
                self.remove_solid(str(key))
            elif kind != "Solid" and key not in self.scene.removed_lights:
                self.remove_light(int(key))
        for k, light in enumerate(self._initial["lights"]):    # fields a supervisor changed
            if self.scene.top_lights()[k] is not light:
                self.scene.set_top_light(k, light)
        self.scene.restore_carried_lights()     # those inside robots and solids too
        self.scene.clear_ink()          # WbPen::reset clears every paint texture
        self.scene.restore_appearances()     # colours a Supervisor set: as loaded
        if self.chargers:
            self._glow()                     # the Chargers' energies as loaded (WbCharger::reset)
        if self.viewpoint_loaded is not None:      # a Viewpoint moveViewpoint moved: where it was loaded
            vp = next(s for s in self.top_level.scenery if s.type == "Viewpoint")
            vp.fields.clear()
            vp.fields.update(self.viewpoint_loaded)
            self.viewpoint_loaded = None
        if self.viewpoint_follow is not None:     # following again from the world file's places
            self.viewpoint_follow = ViewFollow.of(self)
        # radar cross sections a Supervisor set: back to the loaded ones (of the robots and solids still there)
        owners = {k: k[0] if isinstance(k, tuple) else k for k in self._initial["radar_targets"]}
        self.scene.radar_targets = {k: v for k, v in self._initial["radar_targets"].items()
                                    if isinstance(owners[k], int) or owners[k] in self.scene.solid_poses}
        self._counters["resets"] += 1

    @classmethod
    def from_file(cls, path: str | Path, precision: Precision | str = Precision.EXACT, *,
                  limits: WorldLimits | None = None, allow_outside_meshes: bool = False,
                  contact: bool | None = None) -> Simulation:
        """``limits``/``allow_outside_meshes``: see :func:`sensorium.server.world.loader.load_world`;
        ``contact``: kinematic contact on/off (default: the world's ``world_info.contact``). What the
        load left out is ``sim.loaded.report`` (``sim.loaded.warnings``: every message); a loss
        sensors would notice (a robot, a device, a shape) is also one ``WorldLossWarning``."""
        loaded = load_world(path, limits=limits, allow_outside_meshes=allow_outside_meshes)
        warn_losses(loaded.report)
        return cls(loaded, precision, contact=contact, limits=limits, allow_outside_meshes=allow_outside_meshes)

    # ------------------------------------------------------------------ access
    @property
    def precision(self) -> Precision:
        return self.scene.engine.precision

    def robot(self, name: str) -> RobotState:
        try:
            return self.robots[name]
        except KeyError:
            raise KeyError(f"no robot {name!r} (robots: {', '.join(self.robots)})") from None

    def device(self, path: str) -> Device:
        """A device by ``robot/device`` path."""
        robot, sep, name = path.partition("/")
        if not sep:
            raise KeyError(f"device path must be ROBOT/DEVICE, got {path!r}")
        return self.robot(robot).device(name)

    def all_devices(self) -> Iterator[Device]:
        for robot in self.robots.values():
            yield from robot.devices.values()

    def set_solid_pose(self, name: str, translation, rotation=None, quaternion=None) -> None:
        """Move a solid (as ``RobotState.set_pose``: non-finite values or a translation beyond
        ``limits.MAX_COORDINATE_M`` raise ValueError and it stays). One with physics put in the air
        falls from there from rest (sim/falling.py), as Webots' physics drops it."""
        if name not in self.scene.solid_poses:
            raise KeyError(f"no solid {name!r}")
        check_pose(translation, rotation, quaternion)
        self.place_solid(name, moved_pose(self.scene.solid_poses[name], translation, rotation, quaternion))
        # with physics, one put in the air falls from there, from rest, as Webots' physics drops it (a
        # fall it was in ends: it starts over); onto its support it stays, sunk into it it is raised at
        # once (sim/falling.py); one a gripper holds stays with the gripper
        model = next((s for s in self.world.solids if s.name == name), None)
        if model is not None and model.physics and not any(g.held == name for g in self._grippers):
            self.falls.let_go(name, model, self.time_ms)

    def reset_physics(self, solid: str | None = None) -> None:
        """Webots' ``resetPhysics`` on top-level solid ``solid`` (None: every one, ``simulationResetPhysics``):
        velocities zeroed, so a falling one falls again from rest from where it is now (sim/falling.py,
        ``Falls.stop``); nothing else here has a velocity that is not its motors' commands."""
        for name in list(self.falls.falling) if solid is None else [solid]:
            self.falls.stop(name, self.time_ms)

    def place_solid(self, name: str, pose: Pose) -> None:
        """Put a top-level solid at ``pose`` (checked by the caller): the sensors, kinematic contact
        and the terrains see it there from the next measurement."""
        self.scene.set_solid_pose(name, pose)
        if self.contact is not None:
            self.contact.update_solid(name, pose)
        if self.ground is not None:
            self.ground.update_solid(name, pose)

    def ride_solid(self, name: str, robot: str, frame: Pose) -> None:
        """Top-level solid ``name`` (one a Supervisor imported into robot ``robot``'s children) put and kept at
        ``frame`` in the robot's frame: placed there now and after each step's moves, seen there by every
        sensor from the next measurement; :meth:`remove_solid` (and so ``simulationReset``) ends the ride."""
        carrier = self.robots[robot]
        self.solid_riders[name] = (carrier, frame)
        self.place_solid(name, carrier.pose.compose(frame))

    def initial_solid_pose(self, name: str) -> Pose:
        """A top-level solid's pose as the world file (or its import) placed it."""
        initial: dict[str, Pose] = self._initial["solids"]
        return initial[name] if name in initial else self._imported_poses[name]

    def joints_moved(self, robot: RobotState) -> None:
        """A robot's joints were moved from outside (a reset, a Supervisor): what rides on them
        follows, and the distance sensors' ray plans are made again when a device moved."""
        if robot.move_links():
            self._distance_plans.clear()

    def remove_solid(self, name: str) -> None:
        """Take a top-level solid out of the world for good (Webots' ``node.remove()``): from the
        next measurement no sensor sees it, kinematic contact no longer stops robots at it, and
        ``simulationReset`` does not bring it back (Webots' reset adds no removed node)."""
        self._take_out(name)
        self.solid_riders.pop(name, None)
        # what only a removed imported solid needed goes with it (a Supervisor importing and removing for days
        # keeps a name, a node id and a few hundred bytes per removed solid): its model in ``world.solids``
        # (where it keeps its place: the Supervisor numbers nodes by it) becomes its name and DEF alone (a
        # world file's solid keeps its model: the Supervisor's nodes inside it are numbered from it)
        if self._imported_poses.pop(name, None) is None:
            return
        self.imported_written.pop(name, None)
        self.imported_interfaces.pop(name, None)
        regen = getattr(self, "_regen_written", None)
        if regen:
            regen.pop(name, None)
        for k in range(len(self.world.solids) - 1, -1, -1):
            old = self.world.solids[k]
            if old.name == name:
                self.world.solids[k] = _REMOVED.model_copy(update={"name": name, "def_name": old.def_name})
                break

    def _take_out(self, name: str) -> None:
        """A top-level solid out of the scene, kinematic contact and the terrains (a removal, or a solid
        about to be built again under its name)."""
        if name not in self.scene.solid_poses:
            raise KeyError(f"no solid {name!r}")
        self.scene.remove_solid(name)
        if self._sizes is not None:
            self._sizes.pop(name, None)
        if self.contact is not None:
            self.contact.remove_solid(name)
        if self.ground is not None:
            self.ground.remove_solid(name)

    def remove_light(self, index: int) -> None:
        """Take top-level light ``index`` (the world's ``lights`` order) out for good: light sensors
        and cameras stop counting it from their next measurement; a reset does not bring it back."""
        count = len(self.scene.top_lights())
        if not 0 <= index < count or index in self.scene.removed_lights:
            raise KeyError(f"no top-level light {index} (the world has {count}; removed: "
                           f"{sorted(self.scene.removed_lights) or 'none'})")
        self.scene.remove_top_light(index)
        self.imported_written.pop(index, None)

    def next_node_id(self) -> int:
        """The Supervisor id the next imported node gets: after every node the world has had (robots,
        solids and top-level lights, removed ones included, and the top-level nodes not simulated:
        WorldInfo, Viewpoint, ...), so no id is ever reused."""
        return (1 + len(self.robots) + len(self.scene.solid_names) + len(self.scene.top_lights())
                + len(self.top_level.scenery))

    def import_nodes(self, text: str, warnings: list[str] | None = None) -> list[tuple[str, str | int, int]]:
        """Webots' ``importMFNodeFromString`` into the root's children: the string's nodes (solids,
        PROTO instances that are solids, lights; sim/imports.py) join the world, in order, from the
        next measurement (every ray kind, kinematic contact, light sensors, cameras' recognition).
        Returns each as (node type, key: solid name or top-level light index, Supervisor id). A
        string that cannot be imported raises ``ImportRefused`` (one line) and nothing changes.
        ``warnings``: given, it gets one line per value corrected as Webots corrects it."""
        from sensorium.server.sim.imports import check_additions, read_node_string, world_protos
        from sensorium.server.world.geometry import triangle_count
        from sensorium.server.world.limits import ProtoLimits

        if self._import_protos is None:
            self._import_protos = world_protos(self.loaded, ProtoLimits.matching(self.limits))
        nodes = read_node_string(text, self.loaded, self.world, taken=self.scene.solid_name_set, limits=self.limits,
                                 allow_outside_meshes=self.allow_outside_meshes, protos=self._import_protos,
                                 warnings=warnings, suffixes=self._name_suffixes)
        prepared = [self.scene.solid_entries(n.model) if n.type == "Solid" else None for n in nodes]
        added = sum(triangle_count(e.primitive) for p in prepared if p is not None for e in p[1])
        check_additions(self.world, set(self.scene.solid_poses), len(self.scene.world_lights()),
                        self.scene.triangle_count, added, nodes, self.limits, solids_now=sum(self._solid_sizes().values()))
        out: list[tuple[str, str | int, int]] = []
        for node, prep in zip(nodes, prepared):
            node_id = self.next_node_id()
            if prep is not None:
                solid = node.model
                self.world.solids.append(solid)
                self._join_solid(solid, node_id, prep)
                # with physics it falls onto what is under it from now, as Webots' does (sim/falling.py);
                # its pose as imported is where it comes to rest (loadState("__init__") puts it there)
                self._imported_poses[solid.name] = self.falls.let_go(solid.name, solid, self.time_ms)
                key: str | int = solid.name
            else:
                self.world.lights.append(node.model)
                key = self.scene.add_top_light(node.model)
            self.imported.append((node.type, key))
            self.imported_protos[key] = node.proto
            self.imported_interfaces[key] = node.interface
            if node.visual is not None:
                self.imported_visuals[key] = node.visual
            if node.written is not None:       # (a PROTO instance's is built again from it; exportString writes it)
                self.imported_written[key] = node.written
            out.append((node.type, key, node_id))
        return out

    def _solid_sizes(self) -> dict[str, int]:
        """Each top-level solid's solids (itself and its nested children), kept from the first import on."""
        from sensorium.server.sim.imports import solid_count

        if self._sizes is None:
            alive = self.scene.solid_poses
            self._sizes = {s.name: solid_count(s)[0] for s in self.world.solids if s.name in alive}
        return self._sizes

    def _join_solid(self, solid: wm.Solid, node_id: int, prepared: tuple[list, list], again: bool = False) -> None:
        """A top-level solid joins the scene, kinematic contact and the terrains (an import, or a solid built
        again: ``again``, under the name it had)."""
        from sensorium.server.sim.imports import solid_count

        self.scene.add_solid(solid, node_id, prepared, again=again)
        if self._sizes is not None:
            self._sizes[solid.name] = solid_count(solid)[0]
        pose = self.scene.solid_poses[solid.name]
        if self.contact is not None:
            self.contact.add_solid(solid.name, [(e.primitive, local, shape.seen_by in ("both", "bounding"))
                                                for (_, local, shape), e in zip(*prepared)], pose,
                                   ramps=again and self.ground is not None)    # (ramps ground: contact.ramp_top)
        if self.ground is not None and again:
            self.ground.add_solid(solid, pose)

    def _land(self, solid: wm.Solid) -> None:
        """A top-level solid with physics just built again (a PROTO field set) lands at once on what is
        under it now (ground.land_solid, the rule of settle_world at load: it reads as the world file
        written with that value); any other solid stays where it is."""
        to_enu = _TO_ENU[self.world.world_info.coordinate_system]
        pose = self.scene.solid_poses[solid.name]
        landed = land_solid(solid, pose, self.loaded.base_dir, self.landing_ground(solid.name), to_enu)
        if landed is not pose:
            self.place_solid(solid.name, landed)

    def replace_solid(self, name: str, node: Any, node_id: int) -> None:
        """Top-level solid ``name`` built again (a Supervisor set one of its PROTO fields, sim/regenerate.py):
        ``node`` (an ``ImportedNode``, its solid named ``name``) takes its place from the next measurement,
        as Supervisor node ``node_id``, through the removal and import paths (every ray kind, contact, terrains,
        lights, recognition, radar). The world stays within its limits (else ``ImportRefused``, nothing
        changed); its pose as loaded stays the one ``simulationReset`` puts it back at (Webots keeps the
        translation and rotation from the file), and so do the world model's other solids."""
        from sensorium.server.sim.imports import check_additions
        from sensorium.server.world.geometry import triangle_count

        solid = node.model
        assert solid.name == name and name in self.scene.solid_poses
        prepared = self.scene.solid_entries(solid)
        added = sum(triangle_count(e.primitive) for e in prepared[1])
        k = next(i for i in range(len(self.world.solids) - 1, -1, -1) if self.world.solids[i].name == name)
        old = self.world.solids[k]
        others = [s for i, s in enumerate(self.world.solids) if i != k]
        lights_old = sum(1 for _ in solid_lights(old, Pose.identity()))
        sizes = self._solid_sizes()
        check_additions(self.world.model_copy(update={"solids": others}), set(self.scene.solid_poses) - {name},
                        len(self.scene.world_lights()) - lights_old, self.scene.triangle_count
                        - self.scene.solid_triangles(name), added, [node], self.limits,
                        solids_now=sum(sizes.values()) - sizes.get(name, 0))
        self._take_out(name)
        self.world.solids[k] = solid
        self._join_solid(solid, node_id, prepared, again=True)
        # rebuilt with physics, it lands on what is under it, as the world file written so settles at load
        self._land(solid)
        if name in self._initial["solids"]:       # a reset keeps the new values (Webots resets no field)
            targets = self._initial["radar_targets"]
            for key in [t for t in targets if t == name or (isinstance(t, tuple) and t[0] == name)]:
                del targets[key]
            targets.update(solid_radar_targets(solid))
        self._counters["regenerations"] += 1

    @property
    def counters(self) -> dict[str, int]:
        """Work done so far: rays per device kind, ray-engine calls, BVH builds, points built…"""
        out = dict(self._counters)
        eng = self.scene.engine.counters
        out["bvh_builds"] = eng["bvh_builds"]
        out["embree_calls"] = eng["embree_calls"]
        out["engine_rays"] = eng["rays_cast"]
        for key in ("rays_light", "rays_distance", "rays_lidar", "rays_pen", "ink_strokes", "rays_range_finder",
                    "rays_camera", "cast_calls", "points_built", "measurements"):
            out.setdefault(key, 0)
        out["texture_lookups"] = self.scene.textures.lookups if self.scene.textures is not None else 0
        out["contacts"] = self.contact.contacts if self.contact is not None else 0
        out["contact_checks"] = self.contact.checks if self.contact is not None else 0
        return out

    # ------------------------------------------------------------------ stepping
    def _display_screens(self) -> list[list[Any]]:
        """[display, scene shape, the display's measurements last shown] for each Display whose screen
        shape (``screen_shape``: the Shape with an ImageTexture its first child is or holds) is in the
        scene: Webots shows the display's image as that shape's texture, which cameras see."""
        out = []
        for robot in self.robots.values():
            for dev in robot.devices.values():
                k = getattr(dev.config, "screen_shape", None) if dev.kind == "Display" else None
                if k is None or k >= len(robot.model.shapes):
                    continue
                model = robot.model.shapes[k]
                shape = next((i for i in range(len(self.scene.shapes)) if self.scene.shape_model(i) is model), None)
                if shape is not None and model.appearance is not None:
                    out.append([dev, shape, -1])
        return out

    def show_screens(self) -> None:
        """Each display changed since it was last shown becomes its screen shape's texture (the maps
        ``screen_maps`` names: base, emissive or both), from this step's measurements on. A step calls it
        while a device that may see a screen is enabled (``SCREEN_WATCHERS``), a Viewpoint picture
        (viewshot.render) before it looks: a display drawn on while nothing looks costs nothing more."""
        for entry in self._screens:
            dev, shape, shown = entry
            if dev.measurements == shown:
                continue
            entry[2] = dev.measurements
            app = self.scene.shape_model(shape).appearance
            if app is None:           # (a Supervisor took its appearance away: nothing to show it on)
                continue
            url = f"display:{dev.robot_name}/{dev.name}"
            texture = wm.Texture(url=url, filtering=0)
            maps = dev.config.screen_maps
            if maps is None:
                maps = ["texture"] + (["emissive_map"] if app.emissive_map is not None else [])
            update: dict[str, Any] = dict.fromkeys(maps, texture)
            self.scene.set_texture(shape, app.model_copy(update=update), {url: (Path(url), screen_image(dev.pixels))})

    def step(self) -> StepReport:
        """Advance one basic time step and measure every due device at the end-of-step pose."""
        self.time_ms += self.basic_time_step
        self.step_count += 1
        now = self.time_ms
        dt = self.basic_time_step
        radio = self.radio if self.radio else None
        if radio is not None:
            radio.forward()           # packets sent with the step requests leave before anything moves
        if self.chargers:             # at the positions the step starts from (Webots' prePhysicsStep)
            self._charge(dt)
        # robots whose battery emptied: no motion, no new sample until a Charger gives energy (Webots'
        # WbRobot::powerOn(false): motors without torque, sensors not refreshed)
        off = {r.index for r in self._powered if not r.battery.powered} if self._powered else _NOBODY
        if self._pens:                # pens ink at the pose the step starts from (Webots' prePhysicsStep)
            lay_ink(self._pens, self.scene, self.scene.robot_poses, now, self._counters)
        self.scene.evaporate_ink(dt)
        if self._screens and any(d.enabled for d in self._screen_watchers):
            self.show_screens()       # what displays drew (with the step request) shows on their screens
        for speaker in self._speakers:     # sounds and speech played for this step (sim/speaker.py)
            speaker.advance(dt, now)
        moved: list[tuple[RobotState, DifferentialDrive | AckermannDrive | MecanumDrive | OmniDrive | SteeredDrive,
                         tuple[float, float], Pose]] = []
        if self._jointed:             # joints move kinematically (sim/joints.py), and what rides on them
            dt_s = dt * 0.001
            for joint, owner in zip(self._jointed, self._joint_robot):
                if off and owner in off:      # no torque: it holds where it is (README 'Battery and Charger')
                    joint.speed = joint.rate = 0.0
                else:
                    joint.advance(dt_s)
            moved_links = False
            for linked in self._linked:
                moved_links = linked.move_links() or moved_links
            if moved_links:           # distance sensors' stacked poses (and own-body hits) are made again
                self._distance_plans.clear()
        headings: list[float] = []
        for robot in self._driven:
            drive = robot.drive
            assert drive is not None
            robot.pressing = False
            if off and robot.index in off:    # its wheels' motors have no torque: the robot stays
                continue
            start = (drive.x, drive.y)
            yaw0 = drive.yaw
            pose = drive.step(dt)
            if pose is not None:
                moved.append((robot, drive, start, pose))
                headings.append(yaw0)
        if self.contact is not None and moved:
            yaws = np.array([(yaw0, d.yaw) for (_, d, _, _), yaw0 in zip(moved, headings)])
            ends = self.contact.resolve_all([r.index for r, _, _, _ in moved], np.array([s for _, _, s, _ in moved]),
                                            np.array([(d.x, d.y) for _, d, _, _ in moved]), yaws)
            for k, (end, clipped, kept) in enumerate(ends):
                if clipped:
                    robot, drive, start, _ = moved[k]
                    robot.pressing = True
                    if kept != drive.yaw:   # its footprint would have turned into something: the turn cut short
                        drive.yaw = kept
                        drive.turn = math.remainder(kept - headings[k], math.tau) * 1000.0 / dt
                    drive.x, drive.y = float(end[0]), float(end[1])
                    drive.linear = ((drive.x - start[0]) * 1000.0 / dt, (drive.y - start[1]) * 1000.0 / dt)
                    moved[k] = (robot, drive, start, drive.pose())
        if self.ground is not None:   # ride the ground where the (clipped) move ended
            for k, (robot, drive, start, _) in enumerate(moved):
                if drive.rest is not None:
                    drive.settle()
                    moved[k] = (robot, drive, start, drive.pose())
                    if self.contact is not None:
                        self.contact.heights[robot.index] = drive.z    # (ENU, as contact works)
        for robot, _, _, pose in moved:
            self.scene.set_robot_pose(robot.index, pose)
        if self._riders:
            self._carry()
        for name, (robot, frame) in self.solid_riders.items():      # after the robots they ride moved
            self.place_solid(name, robot.pose.compose(frame))
        if self._belts is not None:   # belts carry what lies on them by their motors' travel this step
            self._belts.carry(dt * 0.001)
        if self.falls:                # solids let go fall on before the grippers look (one may catch them)
            self.falls.advance(now)
        for gripper in self._grippers:    # held solids follow their grippers; pumps on attach what they touch
            gripper.carry()
        for con in self._auto_locking:    # Webots attaches a locked auto-lock connector to a present peer
            if con.is_locked:
                con.attach_attempt()
        poses = self.scene.robot_poses
        if self.viewpoint_follow is not None:    # the Viewpoint moves as what it follows moved (WbViewpoint)
            self.viewpoint_follow.update(self)
        if radio is not None:
            radio.deliver(poses)      # range, cones, line of sight and readings at the end-of-step poses
        # Webots' postPhysicsStep (a world without batteries pays nothing here)
        emptied = [robot for robot in self._powered if robot.battery.drain(dt)] if self._powered else ()
        if off or emptied:            # emptied: off; refilled by a Supervisor and left energy: on, sampling now
            off = {r.index for r in self._powered if not r.battery.powered}
        for robot in emptied:         # powered off: its LEDs go dark, its sensors keep their last values
            for dev in robot.devices.values():
                if isinstance(dev, LED):
                    dev.power_off()
        for robot in self._battery_sensing:
            s = robot.battery_schedule
            if s.period_ms > 0:
                # Webots refreshes the sensor when the battery empties: it reads 0 at once
                if now - s.last_update_ms >= s.period_ms or robot in emptied:
                    # without a battery Webots' sensor reads -1 (WbRobot::currentEnergy)
                    robot.battery_value = robot.battery.energy if robot.battery.present else -1.0
                    s.last_update_ms = now
                    if robot.battery_demanded:
                        self._sample_battery(robot, now)
            else:                     # only its topic wants it: every basic step
                self._sample_battery(robot, now)
        for robot in emptied:         # Webots sends the 0 of an emptied battery whether its sensor is enabled or not
            if robot.battery_schedule.period_ms == 0:     # (WbRobot::writeAnswer's pending value)
                robot.battery_value = 0.0
        if self._by_kind is None:   # devices never change after loading: sort them by kind once
            every = list(self.all_devices())
            self._by_kind = ([d for d in every if isinstance(d, LightSensor)],
                             [d for d in every if isinstance(d, DistanceSensor)],
                             [d for d in every if isinstance(d, Lidar)],
                             [d for d in every if d.kinematic])
            self._tracking = [d for d in every if d.tracks_motion]
            self._bumpers = [d for d in every if isinstance(d, TouchSensor) and d.type_code == 0]
            # cameras and range finders first: a display then sees its attached camera's new image
            self._capturing = sorted((d for d in every if getattr(d, "captures", False)),
                                     key=lambda d: d.kind == "Display")
        all_lights, all_distances, all_lidars, all_kinematic = self._by_kind
        capturing, bumpers = self._capturing, self._bumpers
        if off:                       # a powered-off robot's sensors are not refreshed (WbDevice::isPowerOn)
            all_lights = [d for d in all_lights if d.robot_index not in off]
            all_distances = [d for d in all_distances if d.robot_index not in off]
            all_lidars = [d for d in all_lidars if d.robot_index not in off]
            all_kinematic = [d for d in all_kinematic if d.robot_index not in off]
            capturing = [d for d in capturing if d.robot_index not in off]
            bumpers = [d for d in bumpers if d.robot_index not in off]
        for dev in self._tracking:    # devices that read the motion keep its last poses while enabled
            if dev.enabled:
                dev.track()           # type: ignore[attr-defined]
        for bumper in bumpers:        # a bumper remembers a touch until its next reading (WbTouchSensor)
            if bumper.armed and not bumper.touched and not bumper.schedule.due(now):
                bumper.sample()
        # Schedule.due inlined (a step of 1,000 robots asks 8,000 sensors)
        lights: list[LightSensor] = [d for d in all_lights if (s := d.schedule).period_ms > 0
                                     and now - s.last_update_ms >= s.period_ms]
        distances: list[DistanceSensor] = [d for d in all_distances if (s := d.schedule).period_ms > 0
                                           and now - s.last_update_ms >= s.period_ms]
        lidars: list[Lidar] = [d for d in all_lidars if d.due(now)]
        encoders = 0                  # devices measured from the kinematic world (no rays)
        for enc in all_kinematic:
            if enc.schedule.due(now):
                enc.measure(now)      # type: ignore[attr-defined]
                enc.schedule.last_update_ms = now
                encoders += 1
        for cam in capturing:         # cameras and range finders: their own casts (sim/cameras.py)
            if cam.due(now):
                cam.capture(now, self._counters)
                encoders += 1
        if not (lights or distances or lidars):         # no ray this step (e.g. between sensor periods)
            self._counters["measurements"] += encoders
            return StepReport(now, [])
        work: list[tuple[Any, list[RayRequest]]] = []
        if lights:
            if self._lights_version != self.scene.lights_version:  # a light moved with its owner
                self.lights = lights_from_models(self.scene.sensor_lights())
                self._lights_version = self.scene.lights_version
            batch = LightBatch(lights, poses, self.lights)
            work.append((batch, batch.plan()))
        if distances:
            dbatch = DistanceBatch(distances, poses, self.scene.red, self.scene.roughness,
                                   self._distance_plan(distances), self.scene.engine, self.scene)
            work.append((dbatch, dbatch.plan()))
        for lidar in lidars:
            work.append((lidar, lidar.plan(poses[lidar.robot_index], now, dt,
                                           self.scene.device_body(lidar.robot_index, lidar.on_joint))))
        hits = self._cast_batched([req for _, reqs in work for req in reqs])
        k = 0
        for item, reqs in work:
            mine = hits[k:k + len(reqs)]
            k += len(reqs)
            if isinstance(item, Lidar):
                item.finish(mine, now, self._counters, self.scene.engine.threads)
            else:
                item.finish(mine, now)
        for dev in (*lights, *distances, *(x for x in lidars if not x.rotating)):
            dev.schedule.last_update_ms = now
        measured = [*lights, *distances, *lidars]
        self._counters["measurements"] += len(measured) + encoders
        return StepReport(now, measured)

    def run(self, steps: int) -> None:
        for _ in range(steps):
            self.step()

    def enable_battery_sensor(self, robot: RobotState, period_ms: int) -> None:
        """Webots' wb_robot_battery_sensor_enable: a value every ``period_ms`` from now (0 disables;
        the last value stays)."""
        robot.battery_schedule.enable(period_ms, self.time_ms)
        self._battery_sensed(robot)

    def demand_battery(self, robot: RobotState, on: bool) -> None:
        """The robot's battery topic is wanted (``on``) or not: a wanted battery with a present energy keeps
        a sample (:attr:`RobotState.battery_sample`) at each of its controller's sensor values, or at every
        basic step while its controller's sensor is off; the controller's sensor is left as it asked."""
        robot.battery_demanded = bool(on) and robot.battery.present
        self._battery_sensed(robot)

    def _battery_sensed(self, robot: RobotState) -> None:
        sensed = robot.battery_schedule.period_ms > 0 or robot.battery_demanded
        if sensed and robot not in self._battery_sensing:
            self._battery_sensing.append(robot)
        elif not sensed and robot in self._battery_sensing:
            self._battery_sensing.remove(robot)

    @staticmethod
    def _sample_battery(robot: RobotState, now: int) -> None:
        b = robot.battery
        robot.battery_sample = (b.energy, b.maximum, b.state)
        robot.battery_sampled_at_ms = now
        robot.battery_samples += 1

    def _charge(self, dt: int) -> None:
        """Every Charger's step (sim/battery.py) at the robots' and its solid's present positions; a
        Charger whose solid a Supervisor removed does nothing."""
        positions = np.array([p.translation for p in self.scene.robot_poses], dtype=np.float64).reshape(-1, 3)
        for battery in self._batteries:
            battery.gained = 0.0
        for charger in self.chargers:
            own = self.scene.solid_poses.get(charger.solid)
            if own is not None:
                charger.step(self._batteries, positions, np.asarray(own.translation, dtype=np.float64), dt)
        for charger in self.chargers:   # the robot it gave energy: powered on (WbRobot::setCurrentEnergy); one a
            if charger.robot is not None:  # Supervisor refilled is at its post-physics step (Battery.drain)
                self._batteries[charger.robot].power_back()
        self._glow()

    def _glow(self) -> None:
        """Each Charger's glowing shapes take the emissive colour of its energy now (Webots updates them
        at each Charger step and at a reset)."""
        for charger, shapes, lights in self._glowing:
            if charger.solid in self.scene.solid_poses:
                for k, initial in shapes:
                    self.scene.set_glow(k, charger.glow(initial))
                if lights:         # (their places now: another solid's removal moves them)
                    slots = self.scene.solid_light_slots(charger.solid)
                    for i, initial in lights:
                        self.scene.set_light_color(slots[i], charger.glow(initial))

    def _distance_plan(self, distances: list[DistanceSensor]) -> DistancePlan:
        """The stacked constants of these sensors: built when the set of due sensors changes (a
        few sets alternate at most, e.g. sensors with different periods), then reused."""
        key = tuple(map(id, distances))
        plan = self._distance_plans.get(key)
        if plan is None:
            if len(self._distance_plans) >= 8:
                self._distance_plans.clear()
            bodies = [self.scene.robot_body(i) for i in range(len(self.robots))]
            plan = self._distance_plans[key] = DistancePlan(distances, bodies)
        return plan

    def _joined_mount(self, reqs: list[RayRequest], sizes: list[int]):
        """The mounts of requests cast together, as one array; when every part is a kept Mount
        (or no mount), one joined Mount kept for the same parts step after step, so the engine can
        keep its neighbour list (see RayEngine.cast)."""
        parts = [r.mount for r in reqs]

        def joined() -> np.ndarray:
            return np.concatenate([m if m is not None else np.full(n, -1, dtype=np.int64) for m, n in zip(parts, sizes)])

        if any(m is not None and not isinstance(m, Mount) for m in parts):
            if any(isinstance(m, Mount) and m.own is not None for m in parts):
                return None   # rays that see their own body, beside plain mounts: the general broad phase
            return joined()
        key = tuple(id(m) if m is not None else -n for m, n in zip(parts, sizes))
        kept = self._joined_mounts.get(key)
        if kept is None or any(a is not b for a, b in zip(kept[0], parts)):
            if len(self._joined_mounts) >= 8:
                self._joined_mounts.clear()
            own = np.concatenate([m.own if isinstance(m, Mount) and m.own is not None else np.zeros(n, dtype=bool)
                                  for m, n in zip(parts, sizes)])
            kept = self._joined_mounts[key] = (parts, Mount(joined(), own=own))
        return kept[1]

    def _cast_batched(self, requests: list[RayRequest]) -> list[RayHits]:
        """All rays of a step: one engine call per (ray kind, transparency rule, outputs needed)."""
        results: list[RayHits | None] = [None] * len(requests)
        groups: dict[tuple, list[int]] = {}
        for i, r in enumerate(requests):
            self._counters[f"rays_{r.tag}"] += len(r)
            if len(r):
                # a lidar's scan is a cast of its own: its answer never depends on which other lidars
                # are due this step (FAST traces a one-origin scan as coherent packets, a joined cast
                # as incoherent ones, which can differ for a beam grazing an edge)
                lone = i if r.tag == "lidar" else -1
                groups.setdefault((int(r.kind), r.skip_transparent, r.distance_only, lone), []).append(i)
            else:
                results[i] = RayHits(np.empty(0), np.empty((0, 3)), np.empty(0, dtype=np.int64))
        engine = self.scene.engine
        for (kind, skip, distance_only, _), idx in groups.items():
            reqs = [requests[i] for i in idx]
            sizes = [len(r) for r in reqs]
            self._counters["cast_calls"] += 1
            if len(reqs) == 1:   # one request (a lidar): its arrays as they are, no copies
                r = reqs[0]
                results[idx[0]] = engine.cast(r.origins, r.directions, r.t_near, r.t_far, kind=kind,
                                              exclude_owner=r.exclude_owner, skip_transparent=skip, mount=r.mount,
                                              distance_only=distance_only, directions32=r.directions32)
                continue
            origins = np.concatenate([r.origins for r in reqs])
            dirs = np.concatenate([r.directions for r in reqs])
            t_near = joined(reqs, sizes, "t_near", np.float64)
            t_far = joined(reqs, sizes, "t_far", np.float64)
            owners = joined(reqs, sizes, "exclude_owner", np.int64)
            mount = None
            if any(r.mount is not None for r in reqs):
                mount = self._joined_mount(reqs, sizes)
            hits = engine.cast(origins, dirs, t_near, t_far, kind=kind, exclude_owner=owners, skip_transparent=skip,
                               mount=mount, distance_only=distance_only)
            for i, h in zip(idx, split_hits(hits, sizes)):
                results[i] = h
        return results  # type: ignore[return-value]
