"""Many independent copies of one world stepped together: the batched simulation behind training.

    sim = BatchedSimulation(load_world("arena.yaml"), copies=256, precision="fast")
    sim.reset(np.arange(256), world_seeds)          # every copy as a freshly built world with its seed
    k = sim.device("epuck", "ps0"); sim.enable(k, 64)
    sim.set_wheels(sim.slot("epuck"), left, right)   # (copies,) rad/s
    sim.run(2)
    sim.value(k)                                     # (copies,) the readings

A copy is the whole world: every robot of the world file (its *slots*), its own clock, poses,
wheel motors, device schedules, values and noise streams, the lights its robots carry (at its poses:
batched_lights.py); only what never moves (solids, planes, the world's and solids' lights) is shared
and built once. A step advances the copies named in ``active`` by one basic
time step and measures their due devices; the rays of all copies go out in one cast per ray kind
(:class:`~sensorium.server.raycast.copies.CopyRays`: copies never see each other's robots), and
every device model runs once over all copies' devices of a kind.

Copy ``c`` reproduces :class:`~sensorium.server.sim.simulation.Simulation` built from the world
with copy c's seed, bit for bit, for what it simulates: the drive (the same float64 arc, the same
3x3 products), kinematic contact (the same broad phase per copy, the same narrow phase), light
sensors, distance sensors, lidars (rotating ones: batched_lidar.py), wheel encoders, GPS (local or WGS84
coordinates), compasses, inertial units, gyros, accelerometers, bumpers and altimeters
(batched_kinematic.py), range finders (batched_depth.py), cameras (batched_camera.py), each device's noise
drawn from its own stream (``device_rng(seed, "robot/device")``, drawn ahead in blocks: the same numbers, in
the same order). Tests compare it with the single simulation step by step.

Camera recognition and segmentation: batched_recognition.py (per copy, enabled with
:meth:`BatchedSimulation.recognition_enable`). Not simulated here (use :class:`Simulation`): force TouchSensors,
the kinds without an observation (pens, ...; LEDs are set with ``set_led``, their lights light each copy
while on there, batched_lights.py): pens lay no ink, so a world with a writing pen
and an infra-red sensor or a camera to see its ink is refused. Textured robot bodies are read per copy
(batched_textures.py). A skid-steer robot's wheels of one side are driven together (``set_wheels``).
Car-like robots (``ackermann_drive``) are driven by :mod:`~sensorium.server.sim.batched_car`
(``sim.cars.command``; their encoders read its motors), their moves through the same arc, contact
and placing as the other robots. Mecanum robots (``mecanum_drive``) are driven by
:mod:`~sensorium.server.sim.batched_mecanum` (``sim.mecanum.command``, four wheel speeds) and
omni-wheel robots (``omni_drive``) by :mod:`~sensorium.server.sim.batched_omni` (``sim.omni.command``,
a speed per wheel), both on :mod:`~sensorium.server.sim.batched_holonomic`'s wheels, their moves
through the single drive's exact twist step (:func:`~sensorium.server.sim.batched_holonomic.twist_steps`),
then the same contact and placing. A two-wheel or skid-steer robot whose wheels' centre is off its
origin (``differential_drive.axle_center``) moves by the same twist step (its origin's body twist,
as DifferentialDrive.step), one with ``step_rule: mid_heading`` by Webots' straight segment along the
mid-step heading, the others by their arcs, all in the C drive pass (packets.c, the numpy
path's operations); in a world with car-like, mecanum or omni-wheel robots those take the numpy
drive and the two-wheel robots' wheels and moves are C passes within it.

Joint motors (every motor that is no drive's wheel) move per copy by :mod:`~sensorium.server.sim.batched_joints`
(``sim.joints.command``), before the drives as in Simulation.step; the distance sensors, light sensors,
cameras, range finders and lidars (rotating ones too) riding them cast from each copy's link, and the GPS, compasses,
inertial units, gyros, accelerometers and altimeters riding them measure there (a bumper without shapes
riding one reads its robot's contact). Steered-wheel robots
(``steered_drive``) are driven by :mod:`~sensorium.server.sim.batched_steered` (``sim.steered.command``)
at each copy's steering joints, those with free wheels (a tricycle's, vision_car's) by the single drive's
constrained twist, their free wheels' encoders reading what they rolled.
A link's shapes (``on_joint``) are template bodies of their own in the copies' cast, owned by their
robot (``CopyRays``' link slots), each copy's placed at its robot's pose ∘ its joint's displacement
there as Simulation's scene places a link's body, and numbered as that scene numbers them
(:func:`~sensorium.server.sim.scene.robot_bodies`): every ray of a copy meets its own links, a ray blind to
its robot (``exclude_owner``) its robot's links too (every copy's lidar beams meeting a link: one C
pass for all copies, each copy's packed as its own lidar's); a robot's lights riding a joint are placed in each
copy on its link (batched_lights.py). A distance sensor riding a link with shapes is mounted on that
link's template body (its hits on it made once from its mount, as DistanceBatch's own-body hits), and
so is a lidar, camera or range finder with shapes of its own (its hits on it made once from its mount,
blind to them, as Lidar._own_distances and OwnBodyRays; a hit's normal turned by the copy's robot and
link); the other devices riding one meet it in the copies' cast, through the world's frame as the
single ones do.
Refused (BatchedError, one line): a textured shape or
bumper's shape on a link, a link that bounds its robot while kinematic contact
runs (its footprint would not follow the joint); other devices on a joint, and belts.

In a NUE world (y up) the drive state (x, y, yaw, base, contact) is kept in ENU axes, as the single
simulation's PlanarState keeps it, and the poses are turned into the world's axes when placed; such
worlds take the numpy drive pass (the C pass writes ENU poses).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import distance as dmath
from sensorium.server.devices import lidar as lmath
from sensorium.server.devices import light as light_math
from sensorium.server.devices.lookup import RESOLUTION_OFF, quantize_sensor
from sensorium.server.devices.noise import device_rng
from sensorium.server.raycast import packets
from sensorium.server.raycast.copies import CopyRays
from sensorium.server.raycast.engine import Precision, RayEngine, RayHits, RayKind
from sensorium.server.sim import batched_camera as cam
from sensorium.server.sim import batched_depth as depth
from sensorium.server.sim import batched_joints, batched_lidar
from sensorium.server.sim import batched_kinematic as kin
from sensorium.server.sim import batched_recognition as recog
from sensorium.server.sim.batched_car import CarDrives
from sensorium.server.sim.batched_holonomic import twist_steps
from sensorium.server.sim.batched_lights import CarriedLights, has_carried_lights
from sensorium.server.sim.batched_mecanum import MecanumDrives
from sensorium.server.sim.batched_omni import OmniDrives
from sensorium.server.sim.batched_steered import SteeredDrives
from sensorium.server.sim.batched_textures import RobotTextures, textured_robot
from sensorium.server.sim.batches import DistancePlan, _frames_t, _rotate_t, compose_rotations, joined, split_hits
from sensorium.server.sim.contact import (
    EPS,
    FLOOR,
    Contact,
    Obstacle,
    drive_footprint,
    enu_pose,
    heading,
    robot_obstacles,
    spin_reach,
)
from sensorium.server.sim.ground import (
    Ground,
    band_low,
    ground_rotation,
    ride_height,
    settle_world,
    slope_scales,
    slope_twist,
    support_ceiling,
)
from sensorium.server.sim.motion import (
    _TO_ENU,
    AckermannDrive,
    DifferentialDrive,
    MecanumDrive,
    OmniDrive,
    PlanarState,
    SteeredDrive,
    _rz,
)
from sensorium.server.sim.scene import (
    Scene,
    _entry,
    _shape_info,
    blind_devices,
    charger_glow,
    infra_red_terms,
    primitive_from_model,
    robot_bodies,
    robot_bounding_parts,
    solid_parts,
)
from sensorium.server.sim.sensors import LED, DistanceSensor, Lidar, LightSensor, PositionSensor, self_collision_shapes
from sensorium.server.sim.simulation import SettlingGrounds, lights_from_models
from sensorium.server.world.arrays import unique_ints
from sensorium.server.world.geometry import Pose
from sensorium.server.world.limits import check_pose
from sensorium.server.world.loader import LoadedWorld, from_model
from sensorium.server.world.poses import moved_pose, pose_from_model

__all__ = ["BatchedSimulation", "BatchedError", "DeviceRef", "NoiseStreams", "SUPPORTED_KINDS", "check_observable"]

SUPPORTED_KINDS = ("LightSensor", "DistanceSensor", "Lidar", "PositionSensor", *kin.KINDS, *depth.KINDS, *cam.KINDS)
_TWO_PI = 2.0 * math.pi


class BatchedError(ValueError):
    """The world uses something the batched simulation does not simulate (the message says what)."""


def _refusal(robot: str, config, world_info: wm.WorldInfo) -> str | None:
    """Why the batched simulation does not measure a device (its world-file model) in a world
    with this world_info, or None."""
    if config.device not in SUPPORTED_KINDS:
        return (f"robot {robot!r}: device {config.name!r} is a {config.device}; the batched simulation measures "
                f"{', '.join(SUPPORTED_KINDS)} (use Simulation)")
    return kin.refusal(robot, config, world_info)


def check_observable(world: wm.World, robot: str, names: Iterable[str]) -> None:
    """BatchedError (one line saying why) unless the batched simulation measures each named device
    of the world's robot: the check of :meth:`BatchedSimulation.check_observable`, before anything
    is built (names it does not know are left to the caller)."""
    devices = {d.name: d for r in world.robots if r.name == robot for d in r.devices}
    for name in names:
        why = _refusal(robot, devices[name], world.world_info) if name in devices else None
        if why:
            raise BatchedError(why)


@dataclass(frozen=True, slots=True)
class DeviceRef:
    """A device of a slot, as the batched simulation indexes it: its kind and its column in that
    kind's state arrays (``(copies, devices of the kind)``)."""

    kind: str
    column: int
    slot: int
    name: str


class NoiseStreams:
    """Every (copy, device) noise stream, drawn ahead in blocks of ``block`` standard normals.

    A stream is ``device_rng(world seed of the copy, device path)`` (devices/noise.py), created on
    its first draw after a reseed, as a single simulation creates it; numpy's generator gives the
    same numbers whether drawn one by one or ``block`` at a time, so a value drawn here is the
    value the single simulation draws. :meth:`next` takes one number from many streams at once."""

    def __init__(self, copies: int, paths: Sequence[str], block: int = 64):
        self.paths = list(paths)
        self.block = int(block)
        n = len(self.paths)
        self.buffer = np.zeros((copies, n, self.block))
        self.cursor = np.full((copies, n), self.block, dtype=np.int64)    # block: empty, refill first
        self.rngs: list[list[np.random.Generator | None]] = [[None] * n for _ in range(copies)]
        self.seeds: list[int] = [0] * copies

    def reseed(self, copies: Iterable[int], seeds: Iterable[int]) -> None:
        for c, s in zip(copies, seeds):
            self.seeds[c] = int(s)
            self.rngs[c] = [None] * len(self.paths)
            self.cursor[c] = self.block

    def _refill(self, c: int, d: int) -> None:
        rng = self.rngs[c][d]
        if rng is None:
            rng = self.rngs[c][d] = device_rng(self.seeds[c], self.paths[d])
        self.buffer[c, d] = rng.standard_normal(self.block)
        self.cursor[c, d] = 0

    def next(self, copies: np.ndarray, devices: np.ndarray) -> np.ndarray:
        """One standard normal from each (copy, device) stream named (pairs distinct)."""
        cur = self.cursor[copies, devices]
        empty = (cur >= self.block).nonzero()[0]
        for k in empty.tolist():
            self._refill(int(copies[k]), int(devices[k]))
        if len(empty):
            cur = self.cursor[copies, devices]
        self.cursor[copies, devices] = cur + 1
        return self.buffer[copies, devices, cur]

    def take(self, c: int, d: int, count: int) -> np.ndarray:
        """``count`` standard normals from one stream, in order."""
        out = np.empty(count)
        k = 0
        while k < count:
            if self.cursor[c, d] >= self.block:
                self._refill(c, d)
            a = int(self.cursor[c, d])
            m = min(self.block - a, count - k)
            out[k:k + m] = self.buffer[c, d, a:a + m]
            self.cursor[c, d] = a + m
            k += m
        return out

    def stream(self, c: int, d: int) -> np.random.Generator:
        """The (copy, device) stream itself, for a device that draws other numbers between its
        normals (a camera's noise-mask offsets, uniforms): created without a block drawn ahead, so
        that :func:`batched_depth.draw` then takes every normal from it directly, in the single
        device's order. It must be the stream's first use since a reseed, or all its uses such."""
        rng = self.rngs[c][d]
        if rng is None:
            rng = self.rngs[c][d] = device_rng(self.seeds[c], self.paths[d])
        assert self.cursor[c, d] >= self.block, "a stream drawn ahead cannot interleave other draws"
        return rng


class BatchedSimulation:
    """``copies`` independent copies of a world stepped together (see the module docstring)."""

    def __init__(self, world: LoadedWorld | wm.World, copies: int, precision: Precision | str = Precision.EXACT,
                 base_dir: Path | None = None, contact: bool | None = None, threads: int | None = None):
        if isinstance(world, wm.World):
            world = from_model(world, base_dir)
        if int(copies) < 1:
            raise BatchedError(f"copies must be >= 1, got {copies}")
        self.loaded = world
        self.world = w = world.world
        self.copies = C = int(copies)
        self.basic_time_step = w.world_info.basic_time_step
        self._check_supported()
        # its solids with physics and wheeled robots settled on the ground as Simulation settles them (sim/ground.py)
        self.world = w = settle_world(w, _TO_ENU[w.world_info.coordinate_system], world.source, world.base_dir)[0]
        self._settling = SettlingGrounds(_TO_ENU[w.world_info.coordinate_system], size=self.copies)
        # world axes -> ENU (None in an ENU world): the drive state is ENU, as PlanarState's
        up = w.world_info.coordinate_system
        self.to_enu: np.ndarray | None = _TO_ENU[up]
        base = world.base_dir
        # -- what never moves, once: the solids' scene (static tier, planes), the lights
        self.scene = Scene(w.model_copy(update={"robots": []}), base, precision, images=dict(world.textures))
        self.lights = lights_from_models(self.scene.sensor_lights())
        # lights carried by robots: each copy's at its robots' poses (batched_lights.py); None without any
        self.carried = (CarriedLights(w, self.scene.world_lights(), C) if any(has_carried_lights(r) for r in w.robots)
                        else None)
        n_static = len(self.scene.shapes)
        # -- one template body per robot slot (movable), the copies' robots are its poses
        self.robot_names = [r.name for r in w.robots]
        self.R = R = len(w.robots)
        movers = RayEngine(Precision(precision))
        slot_body: list[int | None] = []
        red, rough = list(self.scene.red[:-1]), list(self.scene.roughness[:-1])
        # the shapes of each device's own Solid (of_device), numbered as the movers' engine numbers
        # them: its visual rays do not see them (own_shapes.py), as in the single simulation
        self._own_shapes: dict[tuple[int, str], frozenset[int]] = {}
        # a robot's links (the shapes riding a joint) are template bodies of their own, owned by the
        # robot, added right after its body as the single scene adds them (so the shapes' numbers
        # are that scene's): their slots follow the robots' (robot slot, joint, body)
        link_slots: list[tuple[int, str, int]] = []
        first = 0
        for i, r in enumerate(w.robots):
            owned: dict[str, set[int]] = {}
            slot_body.append(None)
            for joint, parts in robot_bodies(r):
                body = movers.add_body([_entry(s, base, local) for _, local, s in parts],
                                       pose_from_model(r.pose), owner=i, movable=True)
                if joint is None:
                    slot_body[i] = body
                else:
                    link_slots.append((i, joint, body))
                for k, (_, _, shape) in enumerate(parts):
                    for device in blind_devices(shape):
                        owned.setdefault(device, set()).add(first + k)
                first += len(parts)
                for name, _, shape in parts:
                    info = _shape_info(name, i, shape)
                    red.append(info.red)
                    rough.append(info.roughness)
            self._own_shapes.update({(i, d): frozenset(ids) for d, ids in owned.items()})
        if threads is not None:       # the cores a large cast may use (RayEngine.threads; same bits on any number)
            if int(threads) < 1:
                raise BatchedError(f"threads must be >= 1, got {threads}")
            self.scene.engine.threads = movers.threads = int(threads)
        self.link_slots = link_slots
        self.link_bodies = {(i, joint): body for i, joint, body in link_slots}   # (robot slot, joint) -> body
        self._link_cols: tuple[np.ndarray, np.ndarray] | None = None   # (robot slot, joint column) per link
        self.rays = CopyRays(self.scene.engine, movers, slot_body + [b for _, _, b in link_slots], n_static,
                             owner=[*range(R), *(i for i, _, _ in link_slots)],
                             expand=self._with_links if link_slots else None)
        self.red = np.array(red + [1.0])              # per hit shape; -1 (no hit) reads the last entry
        self.roughness = np.array(rough + [0.0])
        self.n_static_shapes = n_static
        # textured robot bodies: their template shapes join the scene's texture sampler, looked up per copy
        self.robot_textures = RobotTextures(self) if any(textured_robot(r) for r in w.robots) else None
        # -- robots: initial poses and drives (the template state every reset starts from)
        self.initial = [pose_from_model(r.pose) for r in w.robots]
        self.has_drive = np.array([r.differential_drive is not None for r in w.robots], dtype=bool)
        self._driven = self.has_drive.nonzero()[0]
        self.wheel_radius = np.array([r.differential_drive.wheel_radius if r.differential_drive else 0.0
                                      for r in w.robots], dtype=np.float64)
        self.axle = np.array([r.differential_drive.axle_length if r.differential_drive else 1.0
                              for r in w.robots], dtype=np.float64)
        # each side's maxVelocity (a skid-steer side's wheels share theirs: the schema's rule)
        self.max_wheel = np.array([[wm.wheel_max_speed(d, d.left_motor), wm.wheel_max_speed(d, d.right_motor)]
                                   if (d := r.differential_drive) else [0.0, 0.0] for r in w.robots], dtype=np.float64)
        self.motor_names = [(r.differential_drive.left_motor, r.differential_drive.right_motor)
                            if r.differential_drive else ("", "") for r in w.robots]
        # every wheel motor's side (0 left, 1 right): a skid-steer robot's wheels of one side are
        # always commanded together here (set_wheels), so one state per side is each of its wheels
        self.wheel_side: list[dict[str, int]] = [
            {name: side for side, names in enumerate(r.differential_drive.motor_names) for name in names}
            if r.differential_drive else {} for r in w.robots]
        # each side's sign: -1.0 where its wheels are mounted mirrored (reversed_motors: a positive speed rolls
        # them backward), multiplied into the side's speed after its mean, as DifferentialDrive.step does
        self.wheel_sign = np.array([r.differential_drive.side_signs if r.differential_drive else (1.0, 1.0)
                                    for r in w.robots], dtype=np.float64).reshape(-1, 2)
        self._any_reversed = bool((self.wheel_sign < 0.0).any())
        self.side_wheels = np.array([[len(n) for n in r.differential_drive.motor_names] if r.differential_drive
                                     else [1, 1] for r in w.robots], dtype=np.int64)
        # a two-wheel robot's wheels' centre (axle_center, x forward and y left of its origin): where it
        # is off the origin the robot moves by its origin's body twist (twist_steps), not the arc
        self.axle_center = np.array([r.differential_drive.axle_center if r.differential_drive else (0.0, 0.0)
                                     for r in w.robots], dtype=np.float64).reshape(-1, 2)
        self.off_centre = (self.axle_center != 0.0).any(axis=1)
        self._any_off_centre = bool(self.off_centre.any())
        # a two-wheel robot with step_rule mid_heading (Webots' rule without Physics, always about its origin:
        # never off centre) moves by the straight segment along its mid-step heading (_mid_heading_steps)
        self.mid_heading = np.array([r.differential_drive is not None and r.differential_drive.step_rule == "mid_heading"
                                     for r in w.robots], dtype=np.uint8)
        self._any_mid_heading = bool(self.mid_heading.any())
        # the terrains robots ride (sim/ground.py; None in a world without one: heights never change)
        self.ground = Ground.from_world(w, self.scene.solid_poses, self.to_enu)
        # each robot's band bottom below its origin (its support ceiling's, ground.band_low; 0 without a ground)
        # (a robot moved by Webots' kinematic rule, mid_heading, rides no ground: Simulation's RobotState)
        self.band_low = np.array([band_low(robot_bounding_parts(r, base), self.initial[i], self.to_enu)
                                  if self.ground is not None and not self.mid_heading[i] else 0.0
                                  for i, r in enumerate(w.robots)], dtype=np.float64)
        self._templates: list[PlanarState | None] = [
            DifferentialDrive(r.differential_drive, self.initial[i], up=up,
                              ground=None if self.mid_heading[i] else self.ground,
                              band_low=float(self.band_low[i])) if r.differential_drive
            else AckermannDrive(r.ackermann_drive, self.initial[i], up=up, ground=self.ground,
                                band_low=float(self.band_low[i])) if r.ackermann_drive
            else MecanumDrive(r.mecanum_drive, self.initial[i], up=up, ground=self.ground,
                              band_low=float(self.band_low[i])) if r.mecanum_drive
            else OmniDrive(r.omni_drive, self.initial[i], up=up, ground=self.ground,
                           band_low=float(self.band_low[i])) if r.omni_drive
            else SteeredDrive(r.steered_drive, self.initial[i], up=up, ground=self.ground,
                              band_low=float(self.band_low[i])) if r.steered_drive
            else None for i, r in enumerate(w.robots)]
        # joint motors (every motor but the drives'): their state per copy and what rides them (batched_joints.py)
        self.joints = batched_joints.BatchedJoints(w, C)
        if self.carried is not None:      # the lights riding joints: placed on each copy's links
            self.carried.bind_joints(self.joints)
        # car-like robots: their motors and bicycle model (batched_car.py), None in a world without one
        self.cars = CarDrives(w, C) if any(r.ackermann_drive for r in w.robots) else None
        # mecanum robots: their four wheels and body twist (batched_mecanum.py), None in a world without one
        self.mecanum = (MecanumDrives(self._templates, C) if any(r.mecanum_drive for r in w.robots) else None)
        # omni-wheel robots: their wheels and body twist (batched_omni.py), None in a world without one
        self.omni = OmniDrives(self._templates, C) if any(r.omni_drive for r in w.robots) else None
        # steered-wheel robots: their wheels and body twist at each copy's steering joints (batched_steered.py)
        self.steered = (SteeredDrives(self._templates, C, self.joints) if any(r.steered_drive for r in w.robots)
                        else None)
        # the drives the C drive pass does not step (it moves two-wheel robots by arcs about their
        # origin, or by their origin's twist when their wheels' centre is off it)
        self._numpy_drives = (self.cars is not None or self.mecanum is not None or self.omni is not None
                              or self.steered is not None
                              or self.to_enu is not None)
        # -- per copy state
        self.time_ms = np.zeros(C, dtype=np.int64)
        self._every_copy = np.arange(C)             # (step's live copies when every copy steps; never written)
        self._every_copy.flags.writeable = False
        self.rot = np.zeros((C, R, 3, 3))
        self.pos = np.zeros((C, R, 3))
        self.yaw = np.zeros((C, R))
        self.x = np.zeros((C, R))
        self.y = np.zeros((C, R))
        self.z = np.zeros((C, R))
        self.base = np.zeros((C, R, 3, 3))
        self.target = np.zeros((C, R, 2))        # wheel motors: target position (inf: velocity control)
        self.velocity = np.zeros((C, R, 2))
        self.wheel_angle = np.zeros((C, R, 2))
        self.pressing = np.zeros((C, R), dtype=bool)
        # riding the ground (PlanarState.rest, z0, slope): NaN rest is nothing under it when placed
        self.rest = np.full((C, R), math.nan)
        self.z0 = np.zeros((C, R))
        self.slope = np.zeros((C, R, 2))
        self.tilted = np.zeros((C, R), dtype=bool)
        # -- kinematic contact: the solids' obstacles once, the robots' footprints (and headings) per copy
        use_contact = w.world_info.contact if contact is None else bool(contact)
        self.contact: Contact | None = None
        if use_contact and (self.has_drive.any() or self.cars is not None or self.mecanum is not None
                            or self.omni is not None or self.steered is not None):
            solids = [(s.name, primitive_from_model(shape.geometry, base), local, self.scene.solid_poses[s.name],
                       shape.seen_by in ("both", "bounding"))
                      for s in w.solids for _, local, shape in solid_parts(s, Pose.identity())]
            bound = [(r.name, f"shape {x.name!r}" if x.name else f"shapes[{i}]", x.on_joint) for r in w.robots
                     for i, x in enumerate(r.shapes) if x.on_joint is not None and x.seen_by in ("both", "bounding")]
            if bound:      # Simulation reshapes a robot's footprint as its joints move; the copies' stay as built
                raise BatchedError(f"{self.loaded.source}: robot {bound[0][0]!r}: {bound[0][1]} rides "
                                   f"joint {bound[0][2]!r} and bounds the robot; the batched simulation's kinematic "
                                   "contact does not follow a link (use Simulation, contact: false, or the shape's "
                                   "seen_by: visual)")
            self.contact = Contact(solids, [], self.to_enu)
            feet = [drive_footprint(robot_bounding_parts(r, base), self.initial[i], self.to_enu,
                                    None if (tpl := self._templates[i]) is None else tpl.yaw)
                    for i, r in enumerate(w.robots)]
            self.feet = feet
            nan = math.nan
            self.foot_radius = np.array([f.radius if f else nan for f in feet])
            self.foot_low = np.array([f.z_low if f else nan for f in feet])
            self.foot_high = np.array([f.z_high if f else nan for f in feet])
            self.centres = np.zeros((C, R, 2))
            self.heights = np.zeros((C, R))
            self.foot_yaw = np.zeros((C, R))       # each footprint's heading (Contact.yaw)
            self._shaped = [f is not None and not f.disc for f in feet]
            self.foot_spin = spin_reach(feet)      # a turn's push off what it turns into (Contact._spin)
            # a disc footprint's own radius (foot_radius, the broad phase's, may be wider)
            self.foot_disc = np.array([f.disc_radius if f is not None and f.disc else nan for f in feet])
            self._footless = any(f is None for f in feet)
            self._bounds: list = []                # _solid_bounds' answer and the obstacle list it is for
            self._bounds_of: list | None = None
        # -- devices: one template object per device (its constants); values per copy
        self._build_devices()
        self.counters = {"steps": 0, "copy_steps": 0, "measurements": 0, "resets": 0, "contacts": 0}
        self.reset(np.arange(C), [w.world_info.random_seed] * C)

    # ------------------------------------------------------------------ building
    def _check_supported(self) -> None:
        w = self.world
        if w.world_info.coordinate_system not in _TO_ENU:
            raise BatchedError(f"{self.loaded.source}: the batched simulation drives robots in ENU or NUE worlds only "
                               f"(world_info.coordinate_system is {w.world_info.coordinate_system})")
        # batteries are not drained here: one that can empty (cpuConsumption > 0 and energy now, or a
        # Charger to give it some) would power its robot off in Simulation, so it is refused
        draining = [r for r in w.robots if r.battery and r.cpu_consumption > 0.0 and (r.battery[0] > 0.0 or w.chargers)]
        if draining:
            r = draining[0]
            raise BatchedError(f"{self.loaded.source}: robot {r.name!r}: its battery ({r.battery[0]:g} J, "
                               f"cpu_consumption {r.cpu_consumption:g} W) can empty and power it off; the batched "
                               "simulation drains no battery (use Simulation, or cpu_consumption: 0)")
        glowing, lit = [], []         # Chargers whose shapes glow, whose lights change colour, with their energy
        for c in w.chargers:
            for s in (s for s in w.solids if s.name == c.solid and len(c.battery) == 3):
                shapes, lights = charger_glow(s, c.glow_shapes, c.glow_lights, c.glow_solids)
                parts = [shape for _, _, shape in solid_parts(s, Pose.identity())]
                if any(parts[i].appearance is not None for i in shapes):
                    glowing.append(c.solid)
                if lights:
                    lit.append(c.solid)
        cameras = [(r.name, d.name) for r in w.robots for d in r.devices if d.device == "Camera"]
        if glowing and cameras:       # no Charger runs here: its glow (sim/battery.py) would not follow its energy
            raise BatchedError(f"{self.loaded.source}: Charger {glowing[0]!r}: its shapes glow with its energy, which "
                               f"camera {cameras[0][0]}/{cameras[0][1]} sees; the batched simulation runs no Charger "
                               "(use Simulation, or glow_shapes: 0 and glow_solids: 0)")
        seeing = [(r.name, d.name) for r in w.robots for d in r.devices if d.device in ("Camera", "LightSensor")]
        if lit and seeing:
            raise BatchedError(f"{self.loaded.source}: Charger {lit[0]!r}: its lights' colour follows its energy, which "
                               f"{seeing[0][0]}/{seeing[0][1]} sees; the batched simulation runs no Charger (use "
                               "Simulation, or glow_lights: 0 and glow_solids: 0)")
        riders = [r for r in w.robots if r.carried_by is not None]
        if riders:                    # Simulation._carry moves them with their carriers; no copy here does
            raise BatchedError(f"{self.loaded.source}: robot {riders[0].name!r} rides robot "
                               f"{riders[0].carried_by.robot!r}; the batched simulation carries no robot (use "
                               "Simulation)")
        belts = [(r.name, b.motor) for r in w.robots for b in r.belts]
        if belts:                     # sim/belt.py carries solids here on no copy: refused, not silently still
            raise BatchedError(f"{self.loaded.source}: robot {belts[0][0]!r}: its conveyor belt (motor {belts[0][1]!r}) "
                               "carries solids; the batched simulation moves no belt (use Simulation)")
        pressed = [(r.name, d.name) for r in w.robots if r.self_collision for d in r.devices
                   if d.device == "TouchSensor" and d.type == "bumper"
                   and (own := {x.on_joint for x in r.shapes if x.of_device == d.name
                                and x.seen_by in ("both", "bounding")})
                   and self_collision_shapes(r, d.name, own)]
        if pressed:                   # sensors.self_collision_shapes: not taken here, refused rather than never touched
            raise BatchedError(f"{self.loaded.source}: robot {pressed[0][0]!r}: bumper {pressed[0][1]!r} touches the "
                               "robot's own shapes (selfCollision); the batched simulation does not (use Simulation)")
        for r in w.robots:            # joints move per copy (batched_joints.py): links' shapes and devices ride them
            bumpers = {d.name for d in r.devices if d.device == "TouchSensor"}
            for i, x in enumerate(r.shapes):
                if x.on_joint is None:
                    continue
                what = (f"shape {x.name!r}" if x.name else f"shapes[{i}]") + (f" of {x.of_device!r}" if x.of_device
                                                                            else "")
                why = ("bumper's shapes on a link (its contact does not follow the joint here)"
                       if x.of_device in bumpers else
                       "textured shape on a link" if textured_robot(r.model_copy(update={"body": None, "shapes": [x]}))
                       else None)
                if why:
                    raise BatchedError(f"{self.loaded.source}: robot {r.name!r}: {what} rides joint {x.on_joint!r}; "
                                       f"the batched simulation moves no {why} (use Simulation)")
            # a device riding a link with shapes meets it as the single one does: a distance sensor, or
            # one with shapes of its own, from its mount (on the link's template body), the others
            # through the world's frame (a lidar's Mount, a camera's Riding: the same products)
            for d in r.devices:
                joint = getattr(d, "on_joint", None)
                if joint is None:
                    continue
                if d.device not in batched_joints.RIDING_KINDS:
                    raise BatchedError(f"{self.loaded.source}: robot {r.name!r}: {d.device} {d.name!r} rides joint "
                                       f"{joint!r}; the batched simulation moves distance sensors, light sensors, "
                                       "cameras, range finders, lidars, GPS, compasses, inertial units, gyros, "
                                       "accelerometers, altimeters and bumpers without shapes on joints only "
                                       "(use Simulation)")
        # a VacuumGripper is not stepped here (no service turns its pump on): one on at load would carry a
        # solid in Simulation that stays put here, so it is refused rather than silently different
        pumps = [(r.name, d.name) for r in w.robots for d in r.devices if d.device == "VacuumGripper" and d.is_on]
        if pumps:
            raise BatchedError(f"{self.loaded.source}: robot {pumps[0][0]!r}: vacuum gripper {pumps[0][1]!r} is on at "
                               "load; the batched simulation carries nothing (use Simulation, or its is_on: false)")
        # pens lay no ink here: a world whose ink infra-red sensors or cameras would read is refused,
        # not run with readings that silently differ from the single simulation's
        pens = [(r.name, d.name) for r in w.robots for d in r.devices if d.device == "Pen" and d.write]
        readers = [(r.name, d.name) for r in w.robots for d in r.devices
                   if d.device == "Camera" or (d.device == "DistanceSensor" and d.type == "infra-red")]
        if pens and readers:
            raise BatchedError(f"{self.loaded.source}: robot {pens[0][0]!r}: pen {pens[0][1]!r} writes, and the batched "
                               f"simulation lays no ink, so {readers[0][0]}/{readers[0][1]} would not see it (use "
                               "Simulation, or the pen's write: false)")

    def _build_devices(self) -> None:
        C = self.copies
        self.refs: dict[tuple[int, str], DeviceRef] = {}
        self.light: list[LightSensor] = []
        self.distance: list[DistanceSensor] = []
        self.lidar: list[Lidar] = []
        self.position: list[PositionSensor] = []
        lists: dict[str, list] = {"LightSensor": self.light, "DistanceSensor": self.distance, "Lidar": self.lidar,
                                  "PositionSensor": self.position, **{k: [] for k in (*kin.KINDS, *depth.KINDS, *cam.KINDS)}}
        classes = {"LightSensor": LightSensor, "DistanceSensor": DistanceSensor, "Lidar": Lidar,
                   "PositionSensor": PositionSensor, **kin.CLASSES, **depth.CLASSES, **cam.CLASSES}
        self._lists = lists
        # LEDs: a template each (the single LED's checks and colour), their values per copy
        self._leds: dict[tuple[int, str], tuple[int, LED]] = {}
        for slot, r in enumerate(self.world.robots):
            for d in r.devices:
                if d.device == "LED":
                    self._leds[(slot, d.name)] = (len(self._leds), LED(config=d, robot_index=slot, robot_name=r.name,
                                                                        self_collision=False, world_seed=0,
                                                                        clock=lambda: 0))
        self.led_value = np.zeros((C, len(self._leds)), dtype=np.int64)
        for slot, r in enumerate(self.world.robots):
            for d in r.devices:
                if d.device not in lists or kin.refusal(r.name, d, self.world.world_info):
                    continue
                dev = classes[d.device](config=d, robot_index=slot, robot_name=r.name, self_collision=r.self_collision,
                                        world_seed=0, clock=lambda: 0,
                                        own_shapes=self._own_shapes.get((slot, d.name), frozenset()))
                riding = dev.on_joint is not None and d.device in batched_joints.PLACED_KINDS
                if riding:
                    # its rays are mounted on no body: on a link without shapes as the single simulation's
                    # (Scene.device_body is None); a distance sensor on one with shapes is mounted on
                    # that link's template body (its own-body hits made from its mount, as
                    # DistanceBatch's), a lidar's beams meet it in the cast (_check_supported); a
                    # light sensor's occlusion rays are mounted on nothing in either; each copy's
                    # local pose is the joints' (batched_joints.py)
                    dev.move_with(Pose.identity())
                    link = self.link_bodies.get((slot, dev.on_joint))
                    if d.device == "DistanceSensor":   # on a link with shapes: mounted on it, as Simulation's
                        dev.link_body = link
                    elif d.device == "Lidar" and dev.own_shapes and link is not None:
                        # its beams meet its link once, in the link's frame from its mount, blind to its
                        # own shapes (Lidar._own_distances, on the movers' engine), the cast skipping it
                        dev._own_body = (_OnEngine(self.rays.movers), link, None)
                    self.joints.add_rider(d.device, len(lists[d.device]), slot, dev.on_joint, dev.mount_pose, dev.local_pose)
                elif d.device == "Lidar" and dev.own_shapes and self.rays.slot_body[slot] is not None:
                    # its beams meet its own robot's body once, in the body frame, blind to its own
                    # shapes (Lidar._own_distances, on the movers' engine)
                    dev._own_body = (_OnEngine(self.rays.movers), self.rays.slot_body[slot], None)
                self.refs[(slot, d.name)] = DeviceRef(d.device, len(lists[d.device]), slot, d.name)
                lists[d.device].append(dev)   # type: ignore[attr-defined]
        # noise streams: one per (copy, device) of every device that can draw (a noisy lookup
        # table or a noise field), in one bank; columns of a kind are consecutive
        self._noise_col: dict[tuple[str, int], int] = {}
        self._noise_of: dict[str, np.ndarray] = {}
        paths = []
        for kind_name, devs in lists.items():
            cols = np.full(len(devs), -1, dtype=np.int64)
            for k, d in enumerate(devs):
                table = getattr(d, "table", None)
                if ((table is not None and table.has_noise) or float(getattr(d.config, "noise", 0.0) or 0.0) > 0.0
                        or kin.draws_noise(d.config) or bool(getattr(d.config, "noise_mask_url", ""))):
                    cols[k] = self._noise_col[(kind_name, k)] = len(paths)
                    paths.append(d.path)
            self._noise_of[kind_name] = cols
        # blocks of up to 256 numbers (a refill is a Python call per stream: ~4 us each, every
        # block's worth of draws) within ~4 MB of buffer, never fewer than 64 (ReachLight x256: 186)
        block = int(min(256, max(64, (1 << 19) // max(1, C * len(paths)))))
        self.noise = NoiseStreams(C, paths, block=block)
        # per kind: schedules (period, last update) per copy and the latest values
        self.period = {k: np.zeros((C, len(v)), dtype=np.int64) for k, v in lists.items()}
        # per kind: whether enable() ever gave one of its devices a period (else none is ever due)
        self._enabled = dict.fromkeys(lists, False)
        self.last = {k: np.zeros((C, len(v)), dtype=np.int64) for k, v in lists.items()}
        self._due_scans: dict[str, packets.DueScan | None] = {}   # per kind: _due's C pass over every copy
        self.values = {k: np.full((C, len(v), *kin.SHAPES.get(k, ())), math.nan) for k, v in lists.items()
                       if k not in ("Lidar", *depth.KINDS, *cam.KINDS)}
        # GPS, Compass, InertialUnit (batched_kinematic.py): their constants and their state beyond values
        self.kinematic = kin.KinematicDevices(self, lists)
        # range finders (batched_depth.py): their pixel rays' constants, every copy's images
        self.depth = depth.DepthDevices(self, lists["RangeFinder"])
        # cameras (batched_camera.py): their pixel rays' constants, every copy's BGRA images
        self.camera = cam.CameraDevices(self, lists["Camera"])
        # their recognition and segmentation (batched_recognition.py): schedules, objects, images per copy
        self.recognition = recog.RecognitionDevices(self, lists["Camera"])
        # rotating lidars (batched_lidar.py): every copy's head; None without one (nothing to filter)
        self.rotating_lidars = batched_lidar.RotatingLidars(self, self.lidar) if any(d.rotating for d in self.lidar) else None
        self._lidar_skips: dict[int, np.ndarray] = {}
        self._lidar_plan: dict[int, tuple] = {}      # per lidar: (copies, each beam's copy, mount slots)
        self._lidar_due: tuple | None = None          # the due lidars' scans (_lidar_scans)
        self._lidar_beam_rows: dict[int, tuple] = {}  # per lidar: its beams' buffers (origins, directions, float32)
        self.range_images = [np.zeros((C, d.config.number_of_layers, d.config.horizontal_resolution), dtype=np.float32)
                             for d in self.lidar]
        # light sensors: constants stacked once
        if self.light:
            self._l_slot = np.array([d.robot_index for d in self.light], dtype=np.int64)
            self._l_rot = np.array([d.local_pose.rotation for d in self.light])
            self._l_pos = np.array([d.local_pose.translation for d in self.light])
            self._l_riding = any(k == "LightSensor" for k, _ in self.joints.riders)
            self._l_filter = np.array([d.config.color_filter for d in self.light], dtype=np.float64)
            self._l_occl = np.array([d.config.occlusion for d in self.light], dtype=bool)
            self._l_excl = np.array([d.exclude_self() for d in self.light], dtype=np.int64)
            self._l_res = np.array([float(d.config.resolution) for d in self.light])
            self._l_tables = _by_table(self.light)
            self._l_table_of = _table_of(self._l_tables, len(self.light))
        # distance sensors: the single simulation's plan over one copy's sensors (groups, own-body hits)
        if self.distance:
            bodies = [self.rays.slot_body[s] for s in range(self.R)]
            self._d_plan = DistancePlan(self.distance, bodies)
            # per engine body (index -1: the last entry, -1): the slot a sensor mounted on it skips in the
            # cast (its robot's, or its link's: its own-body hits are made apart) and the joint column
            # turning a link body (-1: a robot's)
            self._d_mount_slot = np.full(max((b for b in self.rays.slot_body if b is not None), default=0) + 2, -1,
                                         dtype=np.int64)
            self._d_link_joint = self._d_mount_slot.copy()
            for s, b in enumerate(self.rays.slot_body):
                if b is not None:
                    self._d_mount_slot[b] = s
            for i, joint, b in self.link_slots:
                self._d_link_joint[b] = self.joints.of(i, joint)
            self._d_on_link = any(d.link_body is not None for d in self.distance)
            self._d_col = {id(d): k for k, d in enumerate(self.distance)}
            self._d_empty = np.array([not d.config.lookup_table for d in self.distance], dtype=bool)
            self._d_slot = np.array([d.robot_index for d in self.distance], dtype=np.int64)
            self._d_res = np.array([float(d.config.resolution) for d in self.distance])
            self._d_groups = []          # per plan group: where each distance column sits in it (-1: not)
            for g in self._d_plan.groups:
                where = np.full(len(self.distance), -1, dtype=np.int64)
                where[[self._d_col[id(self._d_plan.devices[i])] for i in g.idx.tolist()]] = np.arange(len(g.idx))
                self._d_groups.append((g, where))
            self._d_tables = [(table, np.array([self._d_col[id(self._d_plan.devices[i])] for i in idx.tolist()],
                                               dtype=np.int64)) for table, idx in self._d_plan.tables]
            self._d_table_of = _table_of(self._d_tables, len(self.distance))
            # per plan index: the distance column of a sensor riding a joint (its local pose per copy), else -1
            self._d_riding = np.array([self._d_col[id(d)] if ("DistanceSensor", self._d_col[id(d)]) in self.joints.riders
                                       else -1 for d in self._d_plan.devices], dtype=np.int64)
            self._d_any_riding = bool((self._d_riding >= 0).any())
            self._own_kept: dict[int, tuple] = {}   # per group: its due sensors' own-body hits (_own_rows)
            self._combine_kept: dict[int, tuple] = {}   # per group: its due sensors' CombinePlan
            self._d_rows: list | None = None             # the due sensors' rows (_distance_rows)
        if self.position:
            wheel = []
            for d in self.position:
                m = d.config.motor
                wheel.append(self.wheel_side[d.robot_index].get(m, -1) if m is not None else -1)
            self._p_wheel = np.array(wheel, dtype=np.int64)
            self._p_slot = np.array([d.robot_index for d in self.position], dtype=np.int64)
            self._p_still = np.array([float(d.config.position) for d in self.position])   # no motor: the joint's
            self._p_plain = np.array([float(d.config.noise) <= 0.0 and float(d.config.resolution) <= 0.0
                                      for d in self.position], dtype=bool)

    # ------------------------------------------------------------------ access
    @property
    def precision(self) -> Precision:
        return self.rays.precision

    @precision.setter
    def precision(self, value: Precision | str) -> None:
        self.rays.precision = Precision(value)

    def slot(self, robot: str) -> int:
        try:
            return self.robot_names.index(robot)
        except ValueError:
            raise KeyError(f"no robot {robot!r} (robots: {', '.join(self.robot_names)})") from None

    def device(self, robot: str, name: str) -> DeviceRef:
        slot = self.slot(robot)
        ref = self.refs.get((slot, name))
        if ref is None:
            kinds = {d.name: d for d in self.world.robots[slot].devices}
            if name in kinds:
                raise BatchedError(_refusal(robot, kinds[name], self.world.world_info) or f"{robot}/{name}: not measured")
            raise KeyError(f"robot {robot!r} has no device {name!r} (devices: {', '.join(kinds)})")
        return ref

    def check_observable(self, robot: str, name: str) -> DeviceRef:
        """The device, if the batched simulation measures it (else BatchedError saying why)."""
        ref = self.device(robot, name)
        why = _refusal(robot, self.template(ref).config, self.world.world_info)
        if why:
            raise BatchedError(why)
        return ref

    def template(self, ref: DeviceRef):
        """The device object holding a device's constants (config, lookup table, lidar params)."""
        return self._lists[ref.kind][ref.column]

    def pose(self, copy: int, slot: int) -> Pose:
        return Pose(self.rot[copy, slot], self.pos[copy, slot])

    def value(self, ref: DeviceRef) -> np.ndarray:
        """The latest values of a device in every copy: (copies,) for a light, distance or position
        sensor, (copies, 3) for a GPS (position), a compass (north), an inertial unit (roll, pitch,
        yaw), a gyro (rad/s) or an accelerometer (m/s²)."""
        return self.values[ref.kind][:, ref.column]

    def reading(self, ref: DeviceRef, what: str) -> np.ndarray:
        """A reading of a GPS (``values``, ``speed``, ``speed_vector``), a compass (``values``) or an
        inertial unit (``roll_pitch_yaw``, ``quaternion``) in every copy, as the single simulation's
        attribute of that name."""
        return self.kinematic.reading(ref.kind, ref.column, what)

    def range_image(self, ref: DeviceRef) -> np.ndarray:
        """A lidar's latest range images in every copy, (copies, layers, width) float32, or a range
        finder's, (copies, height, width) float32."""
        if ref.kind in depth.KINDS:
            return self.depth.images[ref.column]
        return self.range_images[ref.column]

    def image(self, ref: DeviceRef) -> np.ndarray:
        """A camera's latest images in every copy, (copies, height, width, 4) uint8 BGRA (as
        ``Camera.image``: black, alpha 255, before the first one)."""
        return self.camera.images[ref.column]

    def recognition_enable(self, ref: DeviceRef, period_ms: int, copies=None) -> None:
        """A camera's ``recognition_enable(period)`` in the named copies (default: all), counted from
        each copy's clock (0 disables it, and the segmentation with it)."""
        self.recognition.enable(self._camera_column(ref), period_ms, slice(None) if copies is None
                                else np.asarray(copies, dtype=np.int64))

    def enable_segmentation(self, ref: DeviceRef, on: bool, copies=None) -> None:
        """A camera's ``enable_segmentation(on)`` in the named copies (default: all)."""
        self.recognition.enable_segmentation(self._camera_column(ref), on, slice(None) if copies is None
                                             else np.asarray(copies, dtype=np.int64))

    def recognition_objects(self, ref: DeviceRef, copy: int) -> list:
        """A camera's latest recognised objects in one copy (``Camera.objects``: RecognisedObject)."""
        return list(self.recognition.objects[copy][self._camera_column(ref)])

    def segmentation_image(self, ref: DeviceRef) -> np.ndarray:
        """A camera's latest segmentation images in every copy, (copies, height, width, 4) uint8 BGRA
        (as ``Camera.segmentation_image``: black, alpha 255, before the first one)."""
        return self.recognition.images[self._camera_column(ref)]

    def _camera_column(self, ref: DeviceRef) -> int:
        if ref.kind != "Camera":
            raise ValueError(f"{self.robot_names[ref.slot]}/{ref.name}: a {ref.kind} has no recognition")
        return ref.column

    # ------------------------------------------------------------------ control
    def reset(self, copies: np.ndarray | Sequence[int], world_seeds: Sequence[int]) -> None:
        """The named copies as a world freshly built with these world seeds: clock 0, robots at
        their world-file poses, wheel motors in position control at 0 (Webots' default), devices
        disabled with no value, every noise stream restarted from its seed. The built scene is
        kept: nothing is rebuilt."""
        idx = np.asarray(copies, dtype=np.int64).reshape(-1)
        if len(idx) != len(world_seeds):
            raise ValueError(f"reset: {len(idx)} copies but {len(world_seeds)} world seeds")
        self.time_ms[idx] = 0
        for r, pose in enumerate(self.initial):
            tpl = self._templates[r]
            if tpl is not None:
                self._take_template(idx, r, tpl)
                pose = tpl.placed(pose)
            self.rot[idx, r] = pose.rotation
            self.pos[idx, r] = pose.translation
            if self.contact is not None:
                enu = enu_pose(pose, self.to_enu)
                self.centres[idx, r] = enu.translation[:2]
                self.heights[idx, r] = enu.translation[2]
                self.foot_yaw[idx, r] = heading(enu) if tpl is None else tpl.yaw
        self.target[idx] = 0.0
        self.velocity[idx] = self.max_wheel
        self.wheel_angle[idx] = 0.0
        if self.cars is not None:
            self.cars.reset(idx)
        if self.mecanum is not None:
            self.mecanum.reset(idx)
        if self.omni is not None:
            self.omni.reset(idx)
        if self.steered is not None:
            self.steered.reset(idx)
        self.joints.reset(idx)
        self.pressing[idx] = False
        self.led_value[idx] = 0                 # LEDs off, their lights too (WbLed::reset)
        if self.carried is not None:
            for slot, name in self.carried.leds:
                self.carried.switch_led(slot, name, idx, False, (0.0, 0.0, 0.0))
        for k in self.period:
            self.period[k][idx] = 0
            self.last[k][idx] = 0
        for v in self.values.values():
            v[idx] = math.nan
        for img in self.range_images:
            img[idx] = 0.0
        if self.rotating_lidars is not None:
            self.rotating_lidars.reset(idx)
        self.kinematic.reset(idx)
        self.depth.reset(idx)
        self.camera.reset(idx)
        self.recognition.reset(idx)
        self.noise.reseed(idx.tolist(), world_seeds)
        self.counters["resets"] += len(idx)

    def set_pose(self, copy: int, slot: int, translation=None, rotation=None, quaternion=None) -> None:
        """Move a robot of one copy (supervisor-style, no contact check), as ``RobotState.set_pose``."""
        check_pose(translation, rotation, quaternion)
        current = self.pose(copy, slot)
        if self.tilted[copy, slot]:   # its own rotation, without the ground's attitude (PlanarState.own_pose)
            own = _rz(float(self.yaw[copy, slot])) @ self.base[copy, slot]
            current = Pose(own if self.to_enu is None else self.to_enu.T @ own, current.translation)
        pose = self._settled(copy, slot, moved_pose(current, translation, rotation, quaternion))
        tpl = self._templates[slot]
        yaw = None
        if tpl is not None:
            tpl.reset(pose)       # the single simulation's own arithmetic (yaw, base, the ground under it)
            self._take_template(np.array([copy]), slot, tpl)
            pose = tpl.placed(pose)
            yaw = tpl.yaw
            tpl.reset(self.initial[slot])
        self.rot[copy, slot] = pose.rotation
        self.pos[copy, slot] = pose.translation
        if self.contact is not None:
            enu = enu_pose(pose, self.to_enu)
            self.centres[copy, slot] = enu.translation[:2]
            self.heights[copy, slot] = enu.translation[2]
            self.foot_yaw[copy, slot] = heading(enu) if yaw is None else yaw
        self.kinematic.placed(copy, slot)     # a jump, not motion, for its gyros and accelerometers

    def _settled(self, copy: int, slot: int, pose: Pose) -> Pose:
        """``Simulation.settled`` in one copy: a wheeled robot put at ``pose`` settles on the ground of
        the solids and of that copy's robots without a drive, with the same arithmetic."""
        return self._settling.settled(self.world.robots[slot], pose, self.world.solids, self.scene, lambda: [
            (r, self.pose(copy, k)) for k, r in enumerate(self.world.robots) if not r.drive_motors])

    def _take_template(self, idx: np.ndarray, slot: int, tpl: PlanarState) -> None:
        """The copies' drive state of a slot from a template drive just reset to a pose."""
        self.x[idx, slot], self.y[idx, slot], self.z[idx, slot], self.yaw[idx, slot] = tpl.x, tpl.y, tpl.z, tpl.yaw
        self.base[idx, slot] = tpl.base
        self.rest[idx, slot] = math.nan if tpl.rest is None else tpl.rest
        self.z0[idx, slot] = tpl.z0
        self.tilted[idx, slot] = tpl.slope is not None
        self.slope[idx, slot] = tpl.slope if tpl.slope is not None else (0.0, 0.0)

    def set_led(self, slot: int, name: str, value: int, copies=None) -> None:
        """``LED.set(value)`` of robot ``slot``'s LED ``name`` in the named copies (default: all): the
        single simulation's checks and colour; its lights (if any) light those copies exactly while it
        is on, in its colour (WbLed)."""
        col, led = self._led(slot, name)
        led.set(value, 0)                       # the single LED's checks (ValueError) and colour
        idx = np.arange(self.copies) if copies is None else np.asarray(copies, dtype=np.int64).reshape(-1)
        self.led_value[idx, col] = int(value)
        if self.carried is not None:
            self.carried.switch_led(slot, name, idx, led.value != 0, led.light_color())

    def led_value_of(self, slot: int, name: str) -> np.ndarray:
        """``LED.get()`` of robot ``slot``'s LED ``name`` in every copy (C,)."""
        return self.led_value[:, self._led(slot, name)[0]].copy()

    def _led(self, slot: int, name: str) -> tuple[int, LED]:
        got = self._leds.get((slot, name))
        if got is None:
            raise KeyError(f"robot {self.robot_names[slot]!r} has no LED {name!r}")
        return got

    def set_wheels(self, slot: int, left, right, copies=None) -> None:
        """Velocity control of a slot's wheels (rad/s, clamped to the maximum as Webots does) in the
        named copies (default: all): ``setPosition(inf)`` and ``setVelocity`` of every wheel motor of
        each side (a skid-steer robot's too)."""
        if self.cars is not None and slot in self.cars.car_of:
            raise ValueError(f"{self.robot_names[slot]}: a car-like robot has no left and right wheels: "
                             "command it with cars.command(slot, right, left, wheel)")
        if self.mecanum is not None and slot in self.mecanum.of:
            raise ValueError(f"{self.robot_names[slot]}: a mecanum robot has no left and right wheels: "
                             "command it with mecanum.command(slot, speeds) (copies, 4)")
        if self.omni is not None and slot in self.omni.of:
            n = int(self.omni.count[self.omni.of[slot]])
            raise ValueError(f"{self.robot_names[slot]}: an omni-wheel robot has no left and right wheels: "
                             f"command it with omni.command(slot, speeds) (copies, {n})")
        if self.steered is not None and slot in self.steered.of:
            n = int(self.steered.count[self.steered.of[slot]])
            raise ValueError(f"{self.robot_names[slot]}: a steered-wheel robot has no left and right wheels: "
                             f"command it with steered.command(slot, speeds) (copies, {n}) and its steering "
                             "joints with joints.command")
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        vmax = self.max_wheel[slot]
        left = np.asarray(left, dtype=np.float64)
        right = np.asarray(right, dtype=np.float64)
        if not (np.isfinite(left).all() and np.isfinite(right).all()):
            raise ValueError(f"{self.robot_names[slot]}: wheel velocities must be finite")
        self.target[idx, slot] = math.inf
        self.velocity[idx, slot, 0] = np.minimum(np.maximum(left, -vmax[0]), vmax[0])
        self.velocity[idx, slot, 1] = np.minimum(np.maximum(right, -vmax[1]), vmax[1])

    def enable(self, ref: DeviceRef, period_ms: int, copies=None) -> None:
        """``enable(period)`` of a device in the named copies (default: all), counted from each
        copy's clock (0 disables)."""
        if isinstance(period_ms, bool) or not isinstance(period_ms, (int, np.integer)) or period_ms < 0:
            raise ValueError(f"sampling period must be an integer >= 0 ms, got {period_ms!r}")
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        self.period[ref.kind][idx, ref.column] = int(period_ms)
        if period_ms > 0:
            self._enabled[ref.kind] = True
        self.last[ref.kind][idx, ref.column] = self.time_ms[idx]
        self.kinematic.enabled(ref.kind, ref.column, idx)

    # ------------------------------------------------------------------ stepping
    def run(self, steps: int, active: np.ndarray | None = None) -> None:
        for _ in range(int(steps)):
            self.step(active)

    def step(self, active: np.ndarray | None = None) -> None:
        """One basic time step of the copies in ``active`` ((copies,) bool; default all): clocks,
        wheels and drives, contact, then every due device measured at the end-of-step poses."""
        C = self.copies
        act = None if active is None else np.asarray(active, dtype=bool).reshape(C)
        dt = self.basic_time_step
        if act is None or act.all():    # every copy (a training step's usual case): no gathers
            live = self._every_copy
            self.time_ms += dt
        else:
            live = act.nonzero()[0]
            if not len(live):
                return
            self.time_ms[live] += dt
        self.counters["steps"] += 1
        self.counters["copy_steps"] += len(live)
        self.joints.step(live, dt * 0.001)       # joints first, as Simulation.step moves them (and their links)
        self._drive(live, dt)
        self._measure_positions(live)
        self.kinematic.measure(live)
        self._measure_rays(live, dt)
        self.recognition.measure(live)

    def _with_links(self, rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every template slot's pose per copy (CopyRays' ``expand``): the robots' (``rot``, ``pos``,
        (C, R, ...)), then each link's, its robot's pose ∘ its joint's displacement in that copy as
        the single scene places a link's body (Pose.compose: the same 3x3 products, stacked)."""
        cols = self._link_cols
        if cols is None:
            cols = self._link_cols = (np.array([i for i, _, _ in self.link_slots], dtype=np.int64),
                                      np.array([self.joints.of(i, j) for i, j, _ in self.link_slots], dtype=np.int64))
        robot, joint = cols
        C = len(rot)
        rr = rot[:, robot]                                    # (C, L, 3, 3)
        lr = self.joints.link_rot[:, joint]
        lp = self.joints.link_pos[:, joint]
        out_rot = np.empty((C, self.R + len(robot), 3, 3))
        out_pos = np.empty((C, self.R + len(robot), 3))
        out_rot[:, :self.R] = rot
        out_pos[:, :self.R] = pos
        out_rot[:, self.R:], out_pos[:, self.R:] = batched_joints.compose_stacked(rr, pos[:, robot], lr, lp)
        return out_rot, out_pos

    # -- motion
    def _drive(self, live: np.ndarray, dt_ms: int) -> None:
        driven = self._driven
        if self._numpy_drives or (self.ground is not None and self.tilted.any()):
            # (robots on a slope: their wheels' speeds are scaled to the horizontal between the wheels'
            # pass and the moves', _over_ground; the C pass does both at once)
            # car-like, mecanum and omni-wheel robots (batched_car.py, batched_holonomic.py): their moves
            # join the numpy path's; a NUE world's poses are turned into its axes there (the C pass
            # writes ENU poses)
            self._drive_numpy(live, driven, dt_ms / 1000.0)
            return
        if not len(driven):
            return
        dt = dt_ms / 1000.0
        step = self._drive_pass()
        if step is None:
            self._drive_numpy(live, driven, dt)
            return
        ct = self.contact
        k = step.run(live, driven, dt, EPS, FLOOR, None if ct is None else (ct._lo, ct._hi, ct._zlo, ct._zhi))
        if not k:
            return
        copies, slots = step.copies[:k], step.slots[:k]
        if step.status[0]:   # an infinite angle: math.cos refuses it, as in the single simulation
            g = step.gathered
            kin.libm_cos_sin(_arc_steps(g[0][:k], g[1][:k], g[2][:k], step.v[:k], step.w[:k], dt)[2])
            raise ValueError("math domain error")
        if step.status[1]:   # a move near something: the narrow phase, slot by slot
            x, y, kept = self._narrow(copies, slots, step.starts[:k], step.ends[:k], step.gathered[2][:k],
                                      step.solid_hit[:k] if len(ct._obs) else None,
                                      step.robot_hit[:k] if self.R > 1 else None, step.near[:k])
            self.x[copies, slots], self.y[copies, slots] = x, y
            if len(kept):     # turns cut short by contact: the heading they kept
                _turn_back(kept, self.yaw[copies[kept], slots[kept]], step.cos, step.sin, step.rz)
        if ct is not None:
            self.foot_yaw[copies, slots] = self.yaw[copies, slots]
        self._place(copies, slots, step.rz[:k], step.base[:k], step.cos[:k], step.sin[:k], step.rot[:k])
        step.scatter(k)

    def _drive_pass(self) -> packets.DriveStep | None:
        """The C pass of :meth:`_drive` over this simulation's state (made once), None without the helper."""
        got = self.__dict__.get("_drive_step", False)
        if got is False:
            contact = None
            if self.contact is not None:
                contact = {"foot_radius": self.foot_radius, "foot_low": self.foot_low, "foot_high": self.foot_high,
                           "heights": self.heights, "centres": self.centres, "spin": self.foot_spin}
            got = self._drive_step = packets.drive_step(
                {"target": self.target, "velocity": self.velocity, "angle": self.wheel_angle,
                 "sides": self.side_wheels, "radius": self.wheel_radius, "axle": self.axle, "x": self.x, "y": self.y,
                 "yaw": self.yaw, "z": self.z, "pressing": self.pressing, "base": self.base, "rot": self.rot,
                 "pos": self.pos, "centre": self.axle_center if self._any_off_centre else None,
                 "mid_heading": self.mid_heading if self._any_mid_heading else None,
                 "sign": self.wheel_sign if self._any_reversed else None}, contact)
        return got

    def _place(self, copies: np.ndarray, slots: np.ndarray, rz: np.ndarray, base: np.ndarray, cos: np.ndarray,
               sin: np.ndarray, out: np.ndarray) -> np.ndarray:
        """The moved robots' ride over the ground (x, y written) and their rotations into ``out``:
        DifferentialDrive.pose's Rz(yaw) @ base (the same 3x3 products, stacked), on a slope with
        the ground's attitude (ground_rotation, as PlanarState.pose)."""
        if self.ground is not None:
            self._ride(copies, slots, self.x[copies, slots], self.y[copies, slots])
        rot = np.matmul(rz, base, out=out)
        if self.ground is not None:
            k = self.tilted[copies, slots].nonzero()[0]
            if len(k):
                c, r = copies[k], slots[k]
                rot[k] = ground_rotation(self.slope[c, r, 0], self.slope[c, r, 1], cos[k], sin[k], self.base[c, r])
        return rot

    def _drive_numpy(self, live: np.ndarray, driven: np.ndarray, dt: float) -> None:
        """:meth:`_drive` without the C drive pass (the same values): a world with car-like, mecanum or
        omni-wheel robots (their moves in numpy; the two-wheel robots' wheels and moves still in C
        passes where the helper is built), a NUE world, or no helper at all."""
        self.pressing[live] = False
        # each kind of drive's moves: (copies, slots, x0, y0, yaw0, x, y, yaw)
        moves = []
        if len(driven):
            wheels = packets.drive_wheels(live, driven, self.target, self.velocity, self.wheel_angle, dt,
                                          self.side_wheels, self.wheel_radius, self.axle,
                                          self.wheel_sign if self._any_reversed else None)
            copies, slots, v, w = wheels if wheels is not None else self._drive_wheels(live, driven, dt)
            if len(copies):
                v, w = self._over_ground(copies, slots, v, w)
                moves.append(self._two_wheel_moves(copies, slots, v, w, dt))
        if self.cars is not None:
            copies, slots, v, w = self.cars.step(live, dt)
            if len(copies):
                v, w = self._over_ground(copies, slots, v, w)
                x0, y0, yaw0 = self.x[copies, slots], self.y[copies, slots], self.yaw[copies, slots]
                x, y, yaw = (_offset_arc_steps(x0, y0, yaw0, v, w, dt, self.cars.rear_axle[slots])
                             if self.cars.offset else _arc_steps(x0, y0, yaw0, v, w, dt))   # offset: origin off the rear axle
                moves.append((copies, slots, x0, y0, yaw0, x, y, yaw))
        # the mecanum and omni-wheel robots' body twists, in one twist_steps call
        twists = [t for t in (d.step(live, dt) for d in (self.mecanum, self.omni, self.steered) if d is not None)
                  if len(t[0])]
        if twists:
            copies, slots, vx, vy, w = (np.concatenate(col) if len(twists) > 1 else col[0] for col in zip(*twists))
            vx, vy, w = self._twist_over_ground(copies, slots, vx, vy, w)
            x0, y0, yaw0 = self.x[copies, slots], self.y[copies, slots], self.yaw[copies, slots]
            moves.append((copies, slots, x0, y0, yaw0, *twist_steps(x0, y0, yaw0, vx, vy, w, dt)))
        if not moves:
            return
        copies, slots, x0, y0, yaw0, x, y, yaw = (np.concatenate(col) if len(moves) > 1 else col[0]
                                                  for col in zip(*moves))
        cos, sin = kin.libm_cos_sin(yaw)
        self.yaw[copies, slots] = yaw
        if self.contact is not None:
            x, y, kept = self._contact(copies, slots, np.stack([x0, y0], axis=1), np.stack([x, y], axis=1), yaw0)
            if len(kept):     # turns cut short by contact: the heading they kept
                _turn_back(kept, self.yaw[copies[kept], slots[kept]], cos, sin, None)
            self.foot_yaw[copies, slots] = self.yaw[copies, slots]
        self.x[copies, slots], self.y[copies, slots] = x, y
        rz = np.zeros((len(yaw), 3, 3))
        rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = cos, -sin, sin, cos, 1.0
        rot = self._place(copies, slots, rz, self.base[copies, slots], cos, sin, np.empty((len(yaw), 3, 3)))
        pos = np.stack([self.x[copies, slots], self.y[copies, slots], self.z[copies, slots]], axis=1)
        if self.to_enu is not None:   # PlanarState.pose's to_enu.T @ r, to_enu.T @ t (0/1 entries: exact, any order)
            back = self.to_enu.T
            rot = np.matmul(back, rot)
            pos = np.matmul(back, pos[:, :, None])[:, :, 0]
        self.rot[copies, slots] = rot
        self.pos[copies, slots] = pos

    def _over_ground(self, copies: np.ndarray, slots: np.ndarray, v: np.ndarray,
                     w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """PlanarState.over_ground for the moving robots: those on a slope (``tilted``) have their speed
        along the ground and turn rate about its normal seen from above (ground.slope_scales, at the
        heading the step starts with, libm's cos and sin as math.cos/math.sin); the others' untouched."""
        if self.ground is None:
            return v, w
        k = self.tilted[copies, slots].nonzero()[0]
        if not len(k):
            return v, w
        c, r = copies[k], slots[k]
        cos, sin = kin.libm_cos_sin(self.yaw[c, r])
        root, turn = slope_scales(self.slope[c, r, 0], self.slope[c, r, 1], cos, sin)
        v, w = v.copy(), w.copy()
        v[k] = v[k] / root
        w[k] = w[k] * turn
        return v, w

    def _twist_over_ground(self, copies: np.ndarray, slots: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                           w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """PlanarState.twist_over_ground for the moving mecanum and omni-wheel robots: those on a slope
        have their body twist in the ground's plane seen from above (ground.slope_twist, at the heading
        the step starts with); the others' untouched."""
        if self.ground is None:
            return vx, vy, w
        k = self.tilted[copies, slots].nonzero()[0]
        if not len(k):
            return vx, vy, w
        c, r = copies[k], slots[k]
        cos, sin = kin.libm_cos_sin(self.yaw[c, r])
        vx, vy, w = vx.copy(), vy.copy(), w.copy()
        vx[k], vy[k], w[k] = slope_twist(self.slope[c, r, 0], self.slope[c, r, 1], cos, sin, vx[k], vy[k], w[k])
        return vx, vy, w

    def _two_wheel_moves(self, copies: np.ndarray, slots: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float):
        """The moving two-wheel robots' (copies, slots, x0, y0, yaw0, x, y, yaw): an arc about the origin,
        or for a robot whose wheels' centre is off its origin the origin's body twist (v + ω cy, −ω cx, ω),
        or for one with step_rule mid_heading the straight segment along its mid-step heading,
        DifferentialDrive.step's; in one C pass (packets.drive_moves) where the helper is built."""
        x0, y0, yaw0 = self.x[copies, slots], self.y[copies, slots], self.yaw[copies, slots]
        centre = self.axle_center if self._any_off_centre else None
        moved = packets.drive_moves(slots, centre, x0, y0, yaw0, v, w, dt,
                                    self.mid_heading if self._any_mid_heading else None)
        if moved is not None:
            return (copies, slots, x0, y0, yaw0, *moved)
        off = self.off_centre[slots]
        mid = self.mid_heading[slots].astype(bool)
        if not off.any() and not mid.any():
            return (copies, slots, x0, y0, yaw0, *_arc_steps(x0, y0, yaw0, v, w, dt))
        x, y, yaw = np.empty_like(x0), np.empty_like(y0), np.empty_like(yaw0)
        on = ~off & ~mid
        x[on], y[on], yaw[on] = _arc_steps(x0[on], y0[on], yaw0[on], v[on], w[on], dt)
        x[mid], y[mid], yaw[mid] = _mid_heading_steps(x0[mid], y0[mid], yaw0[mid], v[mid], w[mid], dt)
        cx, cy, wo = self.axle_center[slots[off], 0], self.axle_center[slots[off], 1], w[off]
        x[off], y[off], yaw[off] = twist_steps(x0[off], y0[off], yaw0[off], v[off] + wo * cy, -wo * cx, wo, dt)
        return copies, slots, x0, y0, yaw0, x, y, yaw

    def _ride(self, copies: np.ndarray, slots: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
        """PlanarState.settle for the moved robots placed over ground: height and slope under them."""
        assert self.ground is not None
        k = (~np.isnan(self.rest[copies, slots])).nonzero()[0]
        if not len(k):
            return
        c, r = copies[k], slots[k]
        ceiling = support_ceiling(self.z[c, r], self.band_low[r], self.z0[c, r], self.rest[c, r])
        found, h, gx, gy = self.ground.under(x[k], y[k], ceiling)
        self.z[c, r] = ride_height(self.z[c, r], self.z0[c, r], self.rest[c, r], found, h)
        self.tilted[c, r] = found & ((gx != 0.0) | (gy != 0.0))
        self.slope[c, r, 0] = np.where(found, gx, 0.0)
        self.slope[c, r, 1] = np.where(found, gy, 0.0)
        if self.contact is not None:
            self.heights[c, r] = self.z[c, r]

    def _drive_wheels(self, live: np.ndarray, driven: np.ndarray, dt: float):
        """The wheels and drives of :meth:`_drive` in numpy (packets.drive_wheels' fallback): the
        wheel angles advanced, and the moving robots' (copies, slots, v, w)."""
        # WheelMotor.advance, element by element the same arithmetic
        tgt = self.target[live][:, driven]
        vel = self.velocity[live][:, driven]
        ang = self.wheel_angle[live][:, driven]
        free = np.isinf(tgt)
        remaining = tgt - ang
        with np.errstate(invalid="ignore"):
            speed = np.minimum(np.abs(vel), np.abs(remaining) / dt) if dt > 0 else np.zeros_like(vel)
            held = np.where(remaining != 0.0, np.copysign(speed, remaining), 0.0)
        omega = np.where(free, vel, held)
        self.wheel_angle[np.ix_(live, driven)] = ang + omega * dt
        wl, wr = omega[..., 0], omega[..., 1]
        counts = self.side_wheels[driven]
        skid = ((counts[:, 0] > 1) | (counts[:, 1] > 1)).nonzero()[0]
        if len(skid):     # DifferentialDrive.step: each side the mean of its (equal) wheels, summed in order
            wl, wr = wl.copy(), wr.copy()
            for j in skid.tolist():
                wl[:, j] = _side_mean(wl[:, j], int(counts[j, 0]))
                wr[:, j] = _side_mean(wr[:, j], int(counts[j, 1]))
        if self._any_reversed:      # a mirrored side rolls backward for a positive speed (exact: a sign)
            sign = self.wheel_sign[driven]
            wl, wr = wl * sign[:, 0], wr * sign[:, 1]
        moving = (wl != 0.0) | (wr != 0.0)                      # (live, driven)
        ci, ri = moving.nonzero()
        copies, slots = live[ci], driven[ri]
        wl, wr = wl[ci, ri], wr[ci, ri]
        rad, axle = self.wheel_radius[slots], self.axle[slots]
        v = rad * (wl + wr) / 2.0
        w = rad * (wr - wl) / axle
        return copies, slots, v, w

    def _contact(self, copies: np.ndarray, slots: np.ndarray, starts: np.ndarray, ends: np.ndarray,
                 yaw0: np.ndarray):
        """Contact.resolve_all per copy: robots in slot order, each against the solids and its own
        copy's other robots (where they are when its turn comes); the same broad phase, the same
        narrow phase (Contact._clip). ``yaw0``: the moves' headings at the start (self.yaw holds
        the end's). Returns the final xy and the moves whose turn was cut short (self.yaw written)."""
        ct = self.contact
        assert ct is not None
        # (Contact.resolve_all's reach: a shaped robot's turn may push it off what it turns into)
        reach = np.hypot(*(ends - starts).T) + EPS + self.foot_spin[slots] * np.minimum(
            np.abs(self.yaw[copies, slots] - yaw0), 2.0)
        Rr = self.foot_radius[slots]
        # where every robot may be during this step: its disc, grown by its own move if it moves
        grow = np.zeros((self.copies, self.R))
        grow[copies, slots] = reach
        native = packets.contact_near(copies, slots, starts, reach, self.foot_radius, self.foot_low, self.foot_high,
                                      self.heights, self.centres, grow, ct._lo, ct._hi, ct._zlo, ct._zhi, EPS,
                                      FLOOR)
        if native is not None:
            solid_hit, robot_hit, near = native
            solid_hit = solid_hit if len(ct._obs) else None
            robot_hit = robot_hit if self.R > 1 else None
        else:
            solid_hit, robot_hit, near = self._contact_near(copies, slots, starts, reach, grow)
        if not near.any():
            # nothing near any move: each ends where Contact._clip without candidates puts it (a
            # robot without a footprint: at its end), whatever the slot order
            self.centres[copies, slots] = np.where(np.isnan(Rr)[:, None], ends, starts + (ends - starts))
            return ends[:, 0], ends[:, 1], _NONE
        return self._narrow(copies, slots, starts, ends, yaw0, solid_hit, robot_hit, near)

    def _solid_bounds(self) -> list[tuple[float, float, float, float, float, float, float, float]]:
        """Per solid obstacle (Contact._obs, made again when they change): its box (lo x, lo y, hi x,
        hi y, as the obstacle's own), a disc holding it (centre x, y and radius, the vertices' mean and
        the farthest vertex plus the round part, widened by 1e-12 of itself) and the largest magnitude
        of its box's coordinates; a wall line's box and disc are infinite."""
        ct = self.contact
        assert ct is not None
        if self._bounds_of is not ct._obs:
            out = []
            for ob in ct._obs:
                (lx, ly), (hx, hy) = ob.lo.tolist(), ob.hi.tolist()
                if ob.normal is not None or not len(ob.points):
                    out.append((lx, ly, hx, hy, 0.0, 0.0, math.inf, math.inf))
                    continue
                pts = ob.points.tolist()
                cx, cy = sum(x for x, _ in pts) / len(pts), sum(y for _, y in pts) / len(pts)
                rho = max(math.hypot(x - cx, y - cy) for x, y in pts) + float(ob.radius)
                size = max(abs(lx), abs(ly), abs(hx), abs(hy))
                out.append((lx, ly, hx, hy, cx, cy, rho * (1.0 + 1e-12) + 1e-300, size))
            self._bounds, self._bounds_of = out, ct._obs
        return self._bounds

    def _out_of_reach(self, copies: np.ndarray, slots: np.ndarray, starts: np.ndarray, ends: np.ndarray,
                      yaw0: np.ndarray, solid_hit: np.ndarray, robot_hit: np.ndarray | None,
                      near: np.ndarray) -> np.ndarray:
        """``near`` without the moves Contact._clip_shaped would end at once, its candidates all out of
        the reach it tests (``_in_reaches``: its turn's, radius x (1 + min(|turn|, 2)), and its move's,
        radius + |move|), which the broad phase, its box grown by both at once, took in: a shaped
        robot's move (not still: a still one ends where it started, not start + 0) near solids only,
        each certainly farther than that reach -- the distance from the start to the solid's box or
        its bounding disc, whichever is larger, beyond the reach by more than twice the narrow phase's
        margin (1e-6 of the coordinates) and far more than rounding. Such a move ends at start + move,
        unclipped, at the heading asked for, as the moves near nothing end: the same bits. ``near``
        itself is returned where no move is cleared."""
        bounds = self._solid_bounds()
        shaped, feet = self._shaped, self.feet
        cleared = []
        for m in near.nonzero()[0].tolist():
            r = int(slots[m])
            if not shaped[r]:
                continue
            (x, y), (ex, ey) = starts[m].tolist(), ends[m].tolist()
            dx, dy = ex - x, ey - y
            # (a robot among the candidates: left to the narrow phase; its row's bytes are 0 or 1)
            if not (dx or dy) or (robot_hit is not None and b"\x01" in robot_hit[m].tobytes()):
                continue
            radius = feet[r].radius
            turn = math.remainder(float(self.yaw[copies[m], r]) - float(yaw0[m]), math.tau)
            reach = radius + math.hypot(dx, dy)
            if turn != 0.0:
                reach = max(reach, radius * (1.0 + min(abs(turn), 2.0)))
            slack = reach + 2e-6 * (1.0 + abs(x) + abs(y) + reach)
            for j in solid_hit[m].nonzero()[0].tolist():
                lx, ly, hx, hy, cx, cy, rho, size = bounds[j]
                gx = lx - x if lx > x else x - hx if x > hx else 0.0
                gy = ly - y if ly > y else y - hy if y > hy else 0.0
                if not max(math.hypot(gx, gy), math.hypot(x - cx, y - cy) - rho) > slack + 1e-12 * size:
                    break
            else:
                cleared.append(m)
        if cleared:
            near = near.copy()
            near[cleared] = False
        return near

    def _narrow(self, copies: np.ndarray, slots: np.ndarray, starts: np.ndarray, ends: np.ndarray, yaw0: np.ndarray,
                solid_hit: np.ndarray | None, robot_hit: np.ndarray | None, near: np.ndarray):
        """The narrow phase of :meth:`_contact` once the broad phase found a move near something:
        Contact._clip (a shaped footprint: Contact._clip_shaped) of each near move (centres and
        footprint headings written); returns the final xy and the moves whose turn was cut short."""
        ct = self.contact
        assert ct is not None
        if solid_hit is not None:
            cut = self._out_of_reach(copies, slots, starts, ends, yaw0, solid_hit, robot_hit, near)
            if cut is not near and not cut.any():      # as _contact ends moves near nothing
                moved = starts + (ends - starts)
                if self._footless:
                    moved = np.where(np.isnan(self.foot_radius[slots])[:, None], ends, moved)
                self.centres[copies, slots] = moved
                return ends[:, 0], ends[:, 1], _NONE
            near = cut
        Rr = self.foot_radius[slots]
        footless = np.isnan(Rr)
        out = ends.copy()
        # copies are independent: the moves of copies where nothing is near end where Contact._clip
        # without candidates puts them, all at once; the others' in slot order, as Contact.resolve_all
        # takes robots in world order (each sees the earlier slots of its copy where they ended, the
        # later ones where they started)
        hot_copy = np.zeros(self.copies, dtype=bool)
        hot_copy[copies[near]] = True
        hot = hot_copy[copies].nonzero()[0]
        # every move's end as the cold ones end (element by element), written for all moves at once;
        # the hot ones' centres as they were kept aside (a robot not yet resolved is where it started)
        # and each overwritten when its turn comes
        moved = starts + (ends - starts)
        if footless.any():
            moved = np.where(footless[:, None], ends, moved)
        hot_list = hot.tolist()
        waiting = {(int(copies[m]), int(slots[m])): self.centres[copies[m], slots[m]].copy() for m in hot_list}
        self.centres[copies, slots] = moved
        kept: list[int] = []
        for m in (hot[np.argsort(slots[hot], kind="stable")].tolist() if len(hot_list) > 1 else hot_list):
            cm, r = int(copies[m]), int(slots[m])
            del waiting[cm, r]
            if footless[m]:
                self.centres[cm, r] = ends[m]
                self.foot_yaw[cm, r] = self.yaw[cm, r]
                continue
            if not near[m]:
                self.centres[cm, r] = starts[m] + (ends[m] - starts[m])
                self.foot_yaw[cm, r] = self.yaw[cm, r]
                continue
            lo = float(self.heights[cm, r] + self.foot_low[r])
            hi = float(self.heights[cm, r] + self.foot_high[r])
            # candidates as resolve_all lists them: solids, then robots, in index order
            near_solids = solid_hit[m].nonzero()[0].tolist() if solid_hit is not None else []
            robot_obs: list[Obstacle] = []
            if robot_hit is not None:
                for j in robot_hit[m].nonzero()[0].tolist():
                    at = waiting.get((cm, j))
                    centre = self.centres[cm, j] if at is None else at
                    band = (float(self.heights[cm, j] + self.foot_low[j]), float(self.heights[cm, j] + self.foot_high[j]))
                    # (a waiting robot's foot_yaw is still its start's)
                    robot_obs += robot_obstacles(j, self.feet[j], centre, float(self.foot_yaw[cm, j]), band)
            foot = self.feet[r]
            if foot.pieces is not None:           # a concave body: its pieces (Contact.resolve_all's path)
                p, clipped, heading_ = ct._clip_pieces(list(foot.pieces), float(self.heights[cm, r]), starts[m].copy(),
                                                       ends[m] - starts[m], float(yaw0[m]), float(self.yaw[cm, r]),
                                                       near_solids, robot_obs, foot)
            else:
                cands = [ct._in_band(ct._obs[j], lo, hi) for j in near_solids] + robot_obs
                if self._shaped[r]:
                    p, clipped, heading_ = ct._clip_shaped(foot, starts[m].copy(), ends[m] - starts[m],
                                                           float(yaw0[m]), float(self.yaw[cm, r]), cands)
                else:
                    p, clipped = ct._clip(starts[m].copy(), ends[m] - starts[m], float(self.foot_disc[r]), cands)
                    heading_ = self.yaw[cm, r]         # a disc turns freely
            if heading_ != self.yaw[cm, r]:          # the turn cut short
                self.yaw[cm, r] = heading_
                kept.append(m)
            self.centres[cm, r] = p
            self.foot_yaw[cm, r] = self.yaw[cm, r]
            if clipped:
                self.pressing[cm, r] = True
                self.counters["contacts"] += 1
                out[m] = p
        return out[:, 0], out[:, 1], np.asarray(kept, dtype=np.int64)

    def _contact_near(self, copies, slots, starts, reach, grow):
        """The broad phase of :meth:`_contact` in numpy (packets.contact_near's fallback):
        (solid_hit (k, S) or None, robot_hit (k, R) or None, near (k,))."""
        ct = self.contact
        assert ct is not None
        k = len(copies)
        Rr = self.foot_radius[slots]
        band_lo = self.heights[copies, slots] + self.foot_low[slots]
        band_hi = self.heights[copies, slots] + self.foot_high[slots]
        box_lo = starts - (reach + Rr)[:, None]
        box_hi = starts + (reach + Rr)[:, None]
        solid_hit = robot_hit = None
        near = np.zeros(k, dtype=bool)
        if len(ct._obs):
            solid_hit = (np.all((ct._lo[None] <= box_hi[:, None]) & (ct._hi[None] >= box_lo[:, None]), axis=2)
                         & (ct._zhi[None] > band_lo[:, None] + FLOOR) & (ct._zlo[None] < band_hi[:, None] - EPS))
            near |= solid_hit.any(axis=1)
        if self.R > 1:
            c = self.centres[copies]                                            # (k, R, 2): before this step
            r_all = self.foot_radius[None, :] + grow[copies]                     # (k, R)
            a_lo = self.heights[copies] + self.foot_low[None, :]
            a_hi = self.heights[copies] + self.foot_high[None, :]
            with np.errstate(invalid="ignore"):
                robot_hit = ((c[:, :, 0] + r_all >= box_lo[:, None, 0]) & (c[:, :, 0] - r_all <= box_hi[:, None, 0])
                             & (c[:, :, 1] + r_all >= box_lo[:, None, 1]) & (c[:, :, 1] - r_all <= box_hi[:, None, 1])
                             & (a_hi > band_lo[:, None] + EPS) & (a_lo < band_hi[:, None] - EPS))
            robot_hit[np.arange(k), slots] = False
            near |= robot_hit.any(axis=1)
        return solid_hit, robot_hit, near

    # -- devices
    def _due(self, kind: str, live: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if not self._enabled[kind]:   # never enabled: every period is 0, nothing is due
            return _NONE, _NONE
        if len(live) == self.copies:    # every copy (live is then 0 ... C-1): the arrays as they are
            scan = self._due_scans.get(kind, False)
            if scan is False:
                scan = self._due_scans[kind] = packets.due_scan(self.time_ms, self.last[kind], self.period[kind])
            if scan is not None:    # (the steps below in one C pass)
                return scan()
            per = self.period[kind]
            due = (per > 0) & (self.time_ms[:, None] - self.last[kind] >= per)
            return due.nonzero()
        per = self.period[kind][live]
        due = (per > 0) & (self.time_ms[live][:, None] - self.last[kind][live] >= per)
        ci, di = due.nonzero()
        return live[ci], di

    def _measure_positions(self, live: np.ndarray) -> None:
        if not self.position:
            return
        copies, cols = self._due("PositionSensor", live)
        if not len(copies):
            return
        wheel = self._p_wheel[cols]
        slot = self._p_slot[cols]
        v = np.where(wheel >= 0, self.wheel_angle[copies, slot, np.maximum(wheel, 0)], self._p_still[cols])
        if self.cars is not None:     # a car's motor's encoder (its steering or a driven wheel)
            self.cars.read_encoders(self.position, copies, cols, v)
        if self.mecanum is not None:  # a mecanum wheel's encoder
            self.mecanum.read_encoders(self.position, copies, cols, v)
        if self.omni is not None:     # an omni wheel's encoder
            self.omni.read_encoders(self.position, copies, cols, v)
        if self.steered is not None:  # a steered wheel's encoder
            self.steered.read_encoders(self.position, copies, cols, v)
        self.joints.read_encoders(self.position, copies, cols, v)   # a joint motor's
        plain = self._p_plain[cols]           # no noise, no resolution: the wheel angle itself
        for k in (~plain).nonzero()[0].tolist():
            col = int(cols[k])
            cfg = self.position[col].config
            noise, res = float(cfg.noise), float(cfg.resolution)
            if noise > 0.0:
                g = self.noise.take(int(copies[k]), self._noise_col[("PositionSensor", col)], 1)[0]
                v[k] = v[k] + float(0.0 + noise * g)
            if res > 0.0:             # PositionSensor.measure's: Webots' discretize
                v[k] = float(quantize_sensor(float(v[k]), res))
        self.values["PositionSensor"][copies, cols] = v
        self.last["PositionSensor"][copies, cols] = self.time_ms[copies]
        self.counters["measurements"] += len(copies)

    def _measure_rays(self, live: np.ndarray, dt: int) -> None:
        work: list = []
        if self.light:
            lc, lcol = self._due("LightSensor", live)
            if len(lc):
                work.append(("light", self._plan_lights(lc, lcol)))
        if self.distance:
            dc, dcol = self._due("DistanceSensor", live)
            if len(dc):
                work.append(("distance", self._plan_distances(dc, dcol)))
        if self.lidar:
            ic, icol = self._due("Lidar", live)
            if self.rotating_lidars is not None:   # due every step while enabled: planned apart
                fixed = (~self.rotating_lidars.mask[icol]).nonzero()[0]
                ic, icol = ic[fixed], icol[fixed]
                swept = self.rotating_lidars.plan(live, dt)
                if swept[0]["items"]:
                    work.append(("rotating_lidar", swept))
            if len(ic):
                work.append(("lidar", self._plan_lidars(ic, icol)))
        if self.depth.devices:
            rc, rcol = self._due("RangeFinder", live)
            if len(rc):
                work.append(("depth", self.depth.plan(rc, rcol)))
        if self.camera.devices:
            cc, ccol = self._due("Camera", live)
            if len(cc):
                work.append(("camera", self.camera.plan(cc, ccol)))
        if not work:
            return
        # one cast per (ray kind, transparency rule, distance only), every copy's rays together
        requests = [req for _, (_, reqs) in work for req in reqs]
        hits = self._cast_requests(requests)
        k = 0
        for what, (state, reqs) in work:
            mine = hits[k:k + len(reqs)]
            k += len(reqs)
            getattr(self, f"_finish_{what}")(state, mine)

    def _cast_requests(self, requests: list[_Rays]) -> list[RayHits]:
        groups: dict[tuple, list[int]] = {}
        for i, r in enumerate(requests):
            # a lidar's scans (coherent runs) are a cast of their own, as the single simulation casts
            # each lidar: joined, runs of another length or another t_near would change FAST's packets
            groups.setdefault((int(r.kind), r.skip, r.distance_only, r.coherent, i if r.coherent else -1), []).append(i)
        out: list[RayHits | None] = [None] * len(requests)
        for (kind, skip, distance_only, coherent, _), idx in groups.items():
            reqs = [requests[i] for i in idx]
            if len(reqs) == 1:
                r = reqs[0]
                out[idx[0]] = self.rays.cast(r.origins, r.directions, r.t_near, r.t_far, RayKind(kind), r.copy,
                                             self.rot, self.pos, r.exclude, r.mount, skip, distance_only, r.d32,
                                             coherent, origin_rows=r.origin_rows, run=r.run)
                continue
            sizes = [len(r.origins) for r in reqs]
            h = self.rays.cast(np.concatenate([r.origins for r in reqs]), np.concatenate([r.directions for r in reqs]),
                               joined(reqs, sizes, "t_near", np.float64), joined(reqs, sizes, "t_far", np.float64),
                               RayKind(kind), joined(reqs, sizes, "copy", np.int64), self.rot, self.pos,
                               joined(reqs, sizes, "exclude", np.int64), joined(reqs, sizes, "mount", np.int64), skip,
                               distance_only, coherent=coherent,
                               run=reqs[0].run if all(r.run == reqs[0].run for r in reqs) else 0)
            for i, hit in zip(idx, split_hits(h, sizes)):
                out[i] = hit
        return out   # type: ignore[return-value]

    # light sensors (LightBatch over every copy's due sensors)
    def _plan_lights(self, copies: np.ndarray, cols: np.ndarray):
        if self.carried is None or not self.carried.switched:
            return self._plan_light_rows(copies, cols)
        # LEDs' lights: the rows of copies whose LEDs are alike (on, colours) share their lights
        keys = [self.carried.key(int(c)) for c in copies]
        order: dict[bytes, list[int]] = {}
        for row, k in enumerate(keys):
            order.setdefault(k, []).append(row)
        groups, requests = [], []
        for rows in order.values():
            r = np.array(rows, dtype=np.int64)
            state, reqs = self._plan_light_rows(copies[r], cols[r])
            groups.append((r, state, len(reqs)))
            requests += reqs
        return {"copies": copies, "cols": cols, "groups": groups}, requests

    def _plan_light_rows(self, copies: np.ndarray, cols: np.ndarray):
        slot = self._l_slot[cols]
        rr = self.rot[copies, slot]
        rt = self.pos[copies, slot]
        local_rot, local_pos = self._l_rot[cols], self._l_pos[cols]
        if self._l_riding:     # a sensor riding a joint: its copy's local pose (batched_joints.py)
            local_rot, local_pos = local_rot.copy(), local_pos.copy()
            for col in unique_ints(cols).tolist():
                key = ("LightSensor", col)
                if key in self.joints.riders:
                    m = (cols == col).nonzero()[0]
                    local_rot[m] = self.joints.local_rot[key][copies[m]]
                    local_pos[m] = self.joints.local_pos[key][copies[m]]
        rot = compose_rotations(rr, local_rot)
        positions = np.einsum("sij,sj->si", rr, local_pos) + rt
        normals = rot[:, :, 0]
        # each row's copy's lights: the shared arrays, or with robots' lights at that copy's poses
        lights = self.lights if self.carried is None else self.carried.rows(self.rot, self.pos, copies)
        att, direct = light_math.light_terms(positions, normals, lights)
        state = {"copies": copies, "cols": cols, "att": att, "direct": direct, "pairs": None, "lights": lights}
        if lights.count == 0 or not self._l_occl[cols].any():
            return state, []
        mask = (direct > 0.0) & self._l_occl[cols][:, None]
        s, light = np.nonzero(mask)
        if s.size == 0:
            return state, []
        state["pairs"] = (s, light)
        if self.carried is None:
            unit, length = light_math.occlusion_segments_many(positions[s], lights)
            rows = np.arange(s.size)
        else:        # per-row lights: every row's segments (elementwise: the same values), the pairs' rows
            unit, length = light_math.occlusion_segments_many(positions, lights)   # type: ignore[arg-type]
            rows = s
        return state, [_Rays(positions[s], unit[rows, light], 0.0, length[rows, light], RayKind.BOUNDING,
                             copies[s], self._l_excl[cols][s], -1)]

    def _irradiance(self, state: dict, hits: list[RayHits]) -> np.ndarray:
        occluded = np.zeros(state["att"].shape, dtype=bool)
        if state["pairs"] is not None:
            s, light = state["pairs"]
            occluded[s, light] = np.isfinite(hits[0].distance)
        return light_math.irradiance_from_terms(state["att"], state["direct"], state["lights"], occluded,
                                                self._l_filter[state["cols"]])

    def _finish_light(self, state: dict, hits: list[RayHits]) -> None:
        copies, cols = state["copies"], state["cols"]
        if "groups" in state:
            e = np.empty(len(cols))
            k = 0
            for rows, sub, n in state["groups"]:
                e[rows] = self._irradiance(sub, hits[k:k + n])
                k += n
        else:
            e = self._irradiance(state, hits)
        values = np.empty(len(cols))
        table_of = self._l_table_of[cols]
        for t, (table, _) in enumerate(self._l_tables):
            sel = (table_of == t).nonzero()[0]
            if not len(sel):
                continue
            if len(table) == 0:        # an empty table is the identity, without noise (devices.md §1.2)
                values[sel] = e[sel]
                continue
            y, n = table.interpolate(e[sel])
            y = self._noisy(y, n, "LightSensor", copies[sel], cols[sel])
            values[sel] = y
        res = self._l_res[cols]
        rounded = res != RESOLUTION_OFF
        if rounded.any():
            values = np.where(rounded, np.trunc(values / np.where(rounded, res, 1.0) + 0.5) * res + 0.0, values)
        self._store("LightSensor", copies, cols, values)

    def _noisy(self, y: np.ndarray, n: np.ndarray, kind: str, copies: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``y (1 + n G)`` where ``n != 0``, G from each (copy, device) stream (add_noise)."""
        noisy = (n != 0.0).nonzero()[0]
        if not len(noisy):
            return y
        g = self.noise.next(copies[noisy], self._noise_of[kind][cols[noisy]])
        y = np.array(y, dtype=np.float64)
        y[noisy] = y[noisy] * (1.0 + n[noisy] * g)
        return y

    def _store(self, kind: str, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        self.values[kind][copies, cols] = values
        self.last[kind][copies, cols] = self.time_ms[copies]
        self.counters["measurements"] += len(copies)

    # distance sensors (DistanceBatch over every copy's due sensors)
    def _plan_distances(self, copies: np.ndarray, cols: np.ndarray):
        plan = self._d_plan
        state = {"copies": copies, "cols": cols, "groups": []}
        reqs: list[_Rays] = []
        groups = self._distance_rows(copies, cols)
        state["kept"] = self._d_rows
        for g, rows, k, pi, c, slot, exclude, mount, t_far, ray_copy, native, local in groups:
            n = g.n
            if native is not None:   # packets.sensor_rays of these sensors
                positions, origins, dirs = native()
            else:
                rr_t = np.ascontiguousarray(self.rot[c, slot].transpose(1, 2, 0))
                if local is None:
                    lrot_t, lpos_t = plan.local_rot_t[:, :, pi], plan.local_pos_t[:, pi]
                else:               # (rows' own local poses: sensors on joints)
                    lrot_t, lpos_t = local[0].transpose(1, 2, 0), local[1].T
                rot_t, pos_t = _frames_t(rr_t, np.ascontiguousarray(lrot_t), np.ascontiguousarray(lpos_t))
                positions = pos_t.T + self.pos[c, slot]
                dirs = _rotate_t(rot_t, np.ascontiguousarray(g.local_dirs_t[:, :, k]))
                origins = np.repeat(positions, n, axis=0)
            reqs.append(_Rays(origins, dirs.reshape(-1, 3), 0.0, t_far, g.kind, ray_copy, exclude, mount, skip=g.skip,
                              run=n, origin_rows=positions))
            state["groups"].append((g, rows, k, c, slot, positions, dirs))
        return state, reqs

    def _distance_rows(self, copies: np.ndarray, cols: np.ndarray) -> list[tuple]:
        """Per plan group with due sensors: (group, rows in the due list, index in the group, index
        in the plan's stacked constants, copy, slot, each ray's excluded and mount slot, far limit
        and copy, their world rays' C pass or None), kept while the same sensors of the same copies
        are due (step after step)."""
        kept = self._d_rows
        if kept is not None and np.array_equal(kept[0], copies) and np.array_equal(kept[1], cols) \
                and not self._d_any_riding:     # (sensors on joints: their copies' local poses, made each step)
            return kept[2]
        plan = self._d_plan
        out = []
        for g, where in self._d_groups:
            # the group's sensors among the due ones: (row in the due list, index in the group)
            k = where[cols]
            rows = (k >= 0).nonzero()[0]
            if not len(rows):
                continue
            k = k[rows]
            pi = g.idx[k]                                  # index in the plan's stacked constants
            c = copies[rows]
            slot = plan.robot[pi]
            n = g.n
            mount: np.ndarray | int = -1
            if g.mount is not None:
                mount = np.repeat(self._d_mount_slot[g.mount.reshape(-1, n)[k, 0]], n)
            exclude = np.repeat(np.where(g.exclude.reshape(-1, n)[k, 0] >= 0, slot, -1), n)
            t_far = g.far_arg if not isinstance(g.far_arg, np.ndarray) else g.t_far.reshape(-1, n)[k].reshape(-1)
            local_rot, local_pos = plan.local_rot, plan.local_pos
            riding = self._d_riding[pi]
            if self._d_any_riding and (riding >= 0).any():
                # one local pose per row: the plan's, or the copy's for a sensor riding a joint
                local_rot, local_pos = plan.local_rot[pi], plan.local_pos[pi]
                for col in unique_ints(riding[riding >= 0]).tolist():
                    m = (riding == col).nonzero()[0]
                    local_rot[m] = self.joints.local_rot[("DistanceSensor", col)][c[m]]
                    local_pos[m] = self.joints.local_pos[("DistanceSensor", col)][c[m]]
                pi = np.arange(len(pi))
            native = packets.sensor_rays_of(c, slot, self.rot, self.pos, pi, local_rot, local_pos, k, g.local_dirs)
            out.append((g, rows, k, pi, c, slot, exclude, mount, t_far, np.repeat(c, n), native,
                        None if local_rot is plan.local_rot else (local_rot, local_pos)))
        self._d_rows = [copies.copy(), cols.copy(), out, None]    # (the outputs: _distance_outputs)
        return out

    def _finish_distance(self, state: dict, hits: list[RayHits]) -> None:
        plan = self._d_plan
        copies, cols = state["copies"], state["cols"]
        measured = np.full(len(cols), math.nan)
        for (g, rows, k, c, slot, positions, dirs), h in zip(state["groups"], hits):
            S, n = dirs.shape[:2]
            dist, shape, normal = h.distance, h.shape, h.normal
            own = g.own_hits(self.rays.movers, plan.mount_rot, plan.mount_pos) if g.mount is not None else None
            if own is not None:   # the nearer of the cast and the ray's own-body hit (decided once)
                od, osh, onr = self._own_rows(g, own, k)
                win = (od < dist).nonzero()[0]
                if len(win):
                    dist, shape, normal = dist.copy(), shape.copy(), normal.copy()
                    dist[win] = od[win]
                    shape[win] = np.where(osh[win] >= 0, osh[win] + self.n_static_shapes, -1)
                    rr = np.repeat(np.arange(S), n)[win]
                    carrier = self.rot[c[rr], slot[rr]]
                    if self._d_on_link:   # mounted on a link: its copy's displacement turns it too (DistanceBatch)
                        joint = self._d_link_joint[g.mount.reshape(-1, n)[k[rr], 0]]
                        on = (joint >= 0).nonzero()[0]
                        if len(on):
                            carrier[on] = carrier[on] @ self.joints.link_rot[c[rr[on]], joint[on]]
                    normal[win] = np.einsum("sij,sj->si", carrier, onr[win])
            dist = dist.reshape(S, n)
            reflection = None
            if g.kind == RayKind.VISUAL:
                sh = shape.reshape(S, n)
                textures = self.scene.textures
                probe = shape if self.robot_textures is not None else np.where(shape < self.n_static_shapes, shape, -1)
                if textures is not None and np.count_nonzero(textures.textured[probe]):
                    red, rough, occl = self._infra_red_terms(shape, np.repeat(positions, n, axis=0),
                                                             dirs.reshape(-1, 3), dist.reshape(-1), np.repeat(c, n))
                    shade = dmath.reflection_factor(red, rough, occl).reshape(S, n)
                else:
                    shade = dmath.reflection_factor(self.red[sh], self.roughness[sh])
                reflection = np.where(sh >= 0, shade, 1.0)
            measured[rows] = dmath.combine_planned(self._combine_plan(g, k, S, n), dist, dirs,
                                                   normal.reshape(S, n, 3), reflection, packets)
        # DistancePlan.output: lookup (by table), each sensor's noise, resolution
        values = np.zeros(len(cols))
        by_table, res, rounded = self._distance_outputs(state["kept"])
        for table, sel, sel_copies, sel_cols in by_table:
            m = measured if sel is None else measured[sel]
            got = packets.lookup(table, m)
            y, nz = got if got is not None else table.interpolate(m)
            y = self._noisy(y, nz, "DistanceSensor", sel_copies, sel_cols)
            if sel is None:
                values = np.array(y, dtype=np.float64)
            else:
                values[sel] = y
        if rounded is not None:
            q = np.trunc(values / np.where(rounded, res, 1.0) + 0.5) * res + 0.0
            values = np.where(rounded, q, values)
        self._store("DistanceSensor", copies, cols, values)

    def _distance_outputs(self, kept: list) -> tuple:
        """The due distance sensors' outputs by table ((table, rows or None for every row, their
        copies, their columns) per table in use), resolutions and which are rounded (None: none),
        kept with their rows (``kept``: :meth:`_distance_rows`' record of the due set)."""
        if kept[3] is None:
            copies, cols = kept[0], kept[1]
            full = ~self._d_empty[cols]
            table_of = np.where(full, self._d_table_of[cols], -1)
            by_table = []
            for t, (table, _) in enumerate(self._d_tables):
                sel = (table_of == t).nonzero()[0]
                if len(sel):
                    by_table.append((None if len(sel) == len(cols) else sel, copies[sel], cols[sel], table))
            res = self._d_res[cols]
            rounded = full & (res != RESOLUTION_OFF)
            kept[3] = ([(table, sel, c, k) for sel, c, k, table in by_table], res,
                       rounded if np.count_nonzero(rounded) else None)
        return kept[3]

    def _combine_plan(self, g, k: np.ndarray, S: int, n: int) -> dmath.CombinePlan:
        """combine_distance_batch's constants for group ``g``'s sensors ``k``, kept while the same
        sensors are due (step after step)."""
        got = self._combine_kept.get(id(g))
        if got is None or not np.array_equal(got[0], k):
            plan = dmath.CombinePlan(g.types[k], g.weights[k], g.lut_max_range[k], g.sensitivity[k], S, n)
            got = self._combine_kept[id(g)] = (k.copy(), plan)
        return got[1]

    def _own_rows(self, g, own: RayHits, k: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The own-body hits (distance, shape, normal) of the rays of group ``g``'s sensors ``k``,
        kept while the same sensors are due (step after step: a gather of every ray's hit less)."""
        got = self._own_kept.get(id(g))
        if got is None or got[0] is not own or not np.array_equal(got[1], k):
            ray = (k[:, None] * g.n + np.arange(g.n)).reshape(-1)
            got = self._own_kept[id(g)] = (own, k.copy(), own.distance[ray], own.shape[ray], own.normal[ray])
        return got[2], got[3], got[4]

    def _infra_red_terms(self, shape, origins, directions, distance, ray_copy):
        """Scene.infra_red_terms for hits on solids; on a textured robot body, per copy with that copy's
        world-to-shape poses (batched_textures.py); other robot shapes read their colour."""
        red, rough = self.red[shape], self.roughness[shape]
        occl = np.zeros(len(shape))
        on_static = (shape >= 0) & (shape < self.n_static_shapes)
        rows = on_static.nonzero()[0]
        if len(rows):
            r2, g2, o2 = self.scene.infra_red_terms(shape[rows], origins[rows], directions[rows], distance[rows])
            red, rough = red.copy(), rough.copy()
            red[rows], rough[rows], occl[rows] = r2, g2, o2
        textures = self.robot_textures
        if textures is not None:
            rows = ((shape >= self.n_static_shapes) & textures.sampler.textured[shape]).nonzero()[0]
            for q in sorted(set(ray_copy[rows].tolist())):
                rq = rows[ray_copy[rows] == q]
                red[rq], rough[rq], occl[rq] = infra_red_terms(self.red, self.roughness, textures.sampler,
                                                               textures.world_to_shape(q), shape[rq], origins[rq],
                                                               directions[rq], distance[rq])
        return red, rough, occl

    # fixed lidars (Lidar.plan/finish over every copy's due lidars)
    def _plan_lidars(self, copies: np.ndarray, cols: np.ndarray):
        reqs: list[_Rays] = []
        state = {"items": []}
        for col, c, ray_copy, mount, t_far, every in self._lidar_scans(copies, cols):
            lid = self.lidar[col]
            slot = lid.robot_index
            rr = self.rot[c, slot]
            rider = ("Lidar", col)
            if rider in self.joints.riders:     # on a joint: each copy's local pose (batched_joints.py)
                rot = np.matmul(rr, self.joints.local_rot[rider][c])
                org = np.matmul(rr, self.joints.local_pos[rider][c][:, :, None])[:, :, 0] + self.pos[c, slot]
            else:
                rot = np.matmul(rr, lid.local_pose.rotation)                    # Pose.compose, stacked
                org = np.matmul(rr, lid.local_pose.translation[None, :, None])[:, :, 0] + self.pos[c, slot]
            W = len(lid._dir_columns[0])
            got = packets.lidar_beams(rot, org, lid._dir_columns, self._lidar_buffers(col, len(c) * W))
            origins, d, d32 = got if got is not None else _lidar_beams(rot, org, lid._dir_columns)
            reqs.append(_Rays(origins, d, lid.params.near, t_far, RayKind.VISUAL, ray_copy,
                              -1, mount, distance_only=True, d32=d32, coherent=True, origin_rows=org, run=W))
            state["items"].append((col, c, every))
        return state, reqs

    def _lidar_scans(self, copies: np.ndarray, cols: np.ndarray) -> list[tuple]:
        """Per due lidar: (column, the copies scanning, each beam's copy, mount slot(s), far limit,
        whether every copy scans, in order), kept while the same lidars of the same copies are due."""
        kept = self._lidar_due
        if kept is not None and np.array_equal(kept[0], copies) and np.array_equal(kept[1], cols):
            return kept[2]
        out = []
        for col in sorted(set(cols.tolist())):
            lid = self.lidar[col]
            c = copies[cols == col]
            W = len(lid._dir_columns[0])
            ray_copy, mount = self._lidar_rows(col, c, W)
            t_far = lid._t_far if not isinstance(lid._t_far, np.ndarray) else np.tile(lid._t_far.reshape(-1), len(c))
            every = len(c) == self.copies and bool((c == np.arange(len(c))).all())
            out.append((col, c, ray_copy, mount, t_far, every))
        self._lidar_due = (copies.copy(), cols.copy(), out)
        return out

    def _lidar_buffers(self, col: int, rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The beam origins, directions and float32 directions of lidar ``col``'s scans this step,
        written over the last step's (each step's rays are cast and finished within the step)."""
        got = self._lidar_beam_rows.get(col)
        if got is None or len(got[0]) != rows:
            got = self._lidar_beam_rows[col] = (np.empty((rows, 3)), np.empty((rows, 3)),
                                                np.empty((rows, 3), dtype=np.float32))
        return got

    def _lidar_rows(self, col: int, copies: np.ndarray, W: int) -> tuple[np.ndarray, np.ndarray | int]:
        """Per beam of the scans of ``copies``: its copy, and its mount slot (a lidar with own
        shapes never meets its own body in the cast: finish adds those hits; else
        :meth:`_lidar_skip`); kept while the same copies scan (all of them, step after step)."""
        got = self._lidar_plan.get(col)
        if got is not None and np.array_equal(got[0], copies):
            return got[1], got[2]
        lid = self.lidar[col]
        ray_copy = np.repeat(copies, W)
        skip = self._lidar_skip(col)
        if lid._own_body is not None:
            mount: np.ndarray | int = self.slot_of_body(lid._own_body[1])
        elif len(skip) and (skip == skip[0]).all():   # every beam alike: one value (the pairing skips the
            mount = int(skip[0])                       # slot without reading a value per ray)
        else:
            mount = np.tile(skip, len(copies))
        self._lidar_plan[col] = (copies.copy(), ray_copy, mount)
        return ray_copy, mount

    def slot_of_body(self, body: int) -> int:
        """The slot of a template body (a robot's, or a link's): the slot the rays of a device
        meeting that body apart skip in the cast (a housed lidar's ``_own_body``, a housed camera's
        ``own``)."""
        return self.rays.slot_body.index(body)

    def _lidar_skip(self, col: int) -> np.ndarray:
        """Per beam: the lidar's own robot slot where the beam can never meet that robot's body
        (a Webots lidar sees its own robot, so the others are paired with it every scan; a fixed
        lidar's beams never move in the body frame), else -1. Decided once."""
        got = self._lidar_skips.get(col)
        if got is None and ("Lidar", col) in self.joints.riders:   # on a joint: its beams move in the body frame
            got = self._lidar_skips[col] = np.full(len(self.lidar[col]._dir_columns[0]), -1, dtype=np.int64)
        if got is None:
            lid = self.lidar[col]
            slot = lid.robot_index
            x, y, z = lid._dir_columns
            local = lid.local_pose
            dirs = np.stack([x, y, z], axis=1) @ local.rotation.T
            far = lid._t_far.reshape(-1) if isinstance(lid._t_far, np.ndarray) else lid._t_far   # (L, W): planar
            reach = self.rays.may_reach(slot, RayKind.VISUAL, np.broadcast_to(local.translation, dirs.shape), dirs,
                                        lid.params.near, far)
            got = self._lidar_skips[col] = np.where(reach, -1, slot).astype(np.int64)
        return got

    def _finish_lidar(self, state: dict, hits: list[RayHits]) -> None:
        for (col, c, every), h in zip(state["items"], hits):
            lid = self.lidar[col]
            L, W = lid.config.number_of_layers, lid.config.horizontal_resolution
            dist = h.distance.reshape(len(c), L, W)
            if lid._own_body is not None:
                dist = np.minimum(dist, lid._own_distances())
            img = self.range_images[col]
            if lid.params.noise > 0:
                nc = self._noise_col[("Lidar", col)]
                for k, cc in enumerate(c.tolist()):
                    stream = _Stream(self.noise, cc, nc)
                    img[cc] = lmath.ranges_from_hits(lid.params, dist[k], lid._all_dirs, stream)  # type: ignore[arg-type]
            elif lid._factor is None and lid.params.resolution == RESOLUTION_OFF and every:
                # every copy scanned, nothing moves a value, cylindrical: the whole image in one C
                # pass where the helper is (ranges_from_hits' bits, as the single Lidar.finish)
                if not packets.lidar_ranges(np.ascontiguousarray(dist, dtype=np.float64).reshape(-1),
                                            lid.params.min_range, lid.params.max_range, img.reshape(-1)):
                    img[c] = lmath.ranges_from_hits(lid.params, dist, lid._all_dirs, None)
            else:   # element by element: every copy's scans in one call
                img[c] = lmath.ranges_from_hits(lid.params, dist, lid._all_dirs, None)
            if every:
                self.last["Lidar"][:, col] = self.time_ms
            else:
                self.last["Lidar"][c, col] = self.time_ms[c]
            self.counters["measurements"] += len(c)

    def _finish_rotating_lidar(self, state: dict, hits: list[RayHits]) -> None:
        self.rotating_lidars.finish(state, hits)   # type: ignore[union-attr]

    def _finish_depth(self, state: dict, hits: list[RayHits]) -> None:
        self.depth.finish(state, hits)

    def _finish_camera(self, state: dict, hits: list[RayHits]) -> None:
        self.camera.finish(state, hits)

    # ------------------------------------------------------------------ tasks
    def cast(self, copies: np.ndarray, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.BOUNDING,
             exclude_slot=-1, skip_transparent: bool = False, distance_only: bool = False,
             coherent: bool = False, run: int = 0, origin_rows=None) -> RayHits:
        """Rays of the named copies (one entry per ray) against each copy's world, as
        ``scene.engine.cast`` of a single simulation (``exclude_slot``: a robot slot whose body
        the rays ignore, as ``exclude_owner``; ``distance_only``, ``coherent``, ``run``,
        ``origin_rows``: as :meth:`.CopyRays.cast`)."""
        return self.rays.cast(origins, directions, t_near, t_far, RayKind(kind), np.asarray(copies, dtype=np.int64),
                              self.rot, self.pos, exclude_slot, -1, skip_transparent, distance_only=distance_only,
                              coherent=coherent, run=run, origin_rows=origin_rows)


@dataclass(slots=True)
class _Rays:
    """One request of a batched step: rays of several copies."""

    origins: np.ndarray
    directions: np.ndarray
    t_near: np.ndarray | float
    t_far: np.ndarray | float
    kind: RayKind
    copy: np.ndarray
    exclude: np.ndarray | int
    mount: np.ndarray | int
    skip: bool = False
    distance_only: bool = False
    d32: np.ndarray | None = None
    coherent: bool = False     # runs of rays from one origin each (lidars): traced as one lidar's beams
    origin_rows: np.ndarray | None = None   # the distinct origins (the lidars' positions), when known
    run: int = 0   # > 0: runs of this many rays share one origin and one copy (a scan, a sensor's rays)


class _OnEngine:
    """What a device template's own-body cast reads of its scene: the engine holding the robots."""

    def __init__(self, engine: RayEngine):
        self.engine = engine


class _Stream:
    """One (copy, device) noise stream with the interface lidar.ranges_from_hits draws through."""

    def __init__(self, bank: NoiseStreams, copy: int, column: int):
        self.bank, self.copy, self.column = bank, copy, column

    def standard_normal(self, count: int) -> np.ndarray:
        return self.bank.take(self.copy, self.column, int(count))


_NONE = np.zeros(0, dtype=np.int64)
_NONE.setflags(write=False)


def _by_table(devices: list) -> list[tuple]:
    """(table, device columns) for devices sharing a lookup table (tables compare by rows)."""
    out: dict = {}
    for k, d in enumerate(devices):
        out.setdefault(d.table, []).append(k)
    return [(t, np.array(v, dtype=np.int64)) for t, v in out.items()]


def _table_of(tables: list[tuple], n: int) -> np.ndarray:
    """(n,) the index in ``tables`` ((table, device columns) pairs) of each column's table (-1: none)."""
    out = np.full(n, -1, dtype=np.int64)
    for t, (_, members) in enumerate(tables):
        out[members] = t
    return out


def _lidar_beams(rot: np.ndarray, org: np.ndarray, columns) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The beams of n scans of one fixed lidar (packets.lidar_beams' numpy path): origins, directions
    (rot @ each beam's sensor-frame column, _rotate_columns stacked) and the directions as float32,
    (n * W, 3) each."""
    x, y, z = columns
    W = len(x)
    dirs = np.empty((len(rot), W, 3))
    for j in range(3):
        acc = x[None, :] * rot[:, j, 0, None]
        acc += y[None, :] * rot[:, j, 1, None]
        acc += z[None, :] * rot[:, j, 2, None]
        dirs[:, :, j] = acc
    d = dirs.reshape(-1, 3)
    return np.repeat(org, W, axis=0), d, d.astype(np.float32)


def _side_mean(w: np.ndarray, n: int) -> np.ndarray:
    """``sum(w for each of n wheels) / n`` as Python's ``sum`` and one division give it (0 + w + w ...)."""
    acc = 0.0 + w
    for _ in range(n - 1):
        acc = acc + w
    return acc / n


def _offset_arc_steps(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float,
                      a: np.ndarray):
    """motion.offset_arc_step for many robots (``a``: each one's rear axle offset; 0 is
    :func:`_arc_steps` of the robot itself), element by element the same float64 operations."""
    k = (a != 0.0).nonzero()[0]
    if not len(k):
        return _arc_steps(x, y, yaw, v, w, dt)
    ax, ay, ak = x.copy(), y.copy(), a[k]
    c0, s0 = kin.libm_cos_sin(yaw[k])
    ax[k] = x[k] + ak * c0
    ay[k] = y[k] + ak * s0
    x1, y1, yaw1 = _arc_steps(ax, ay, yaw, v, w, dt)
    c1, s1 = kin.libm_cos_sin(yaw1[k])
    x1[k] = x1[k] - ak * c1
    y1[k] = y1[k] - ak * s1
    return x1, y1, yaw1


def _mid_heading_steps(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float):
    """motion.mid_heading_step for many robots, element by element the same float64 operations."""
    dyaw = w * dt
    cm, sm = kin.libm_cos_sin(yaw + 0.5 * dyaw)
    return x + v * dt * cm, y + v * dt * sm, np.remainder(yaw + dyaw + math.pi, _TWO_PI) - math.pi


def _arc_steps(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float):
    """motion.arc_step for many robots, element by element the same float64 operations."""
    dyaw = w * dt
    straight = np.abs(dyaw) < 1e-9
    n_straight = int(np.count_nonzero(straight))
    if n_straight == 0:   # every robot turns (or every one goes straight): whole arrays, no gathers
        r = v / w
        c1, s1 = kin.libm_cos_sin(yaw + dyaw)
        c0, s0 = kin.libm_cos_sin(yaw)
        return x + r * (s1 - s0), y - r * (c1 - c0), np.remainder(yaw + dyaw + math.pi, _TWO_PI) - math.pi
    if n_straight == len(x):
        cm, sm = kin.libm_cos_sin(yaw + 0.5 * dyaw)
        return (x + v * dt * cm, y + v * dt * sm, np.remainder(yaw + dyaw + math.pi, _TWO_PI) - math.pi)
    xo, yo = x.copy(), y.copy()
    s = straight.nonzero()[0]
    if len(s):
        mid = yaw[s] + 0.5 * dyaw[s]
        cm, sm = kin.libm_cos_sin(mid)
        xo[s] = x[s] + v[s] * dt * cm
        yo[s] = y[s] + v[s] * dt * sm
    t = (~straight).nonzero()[0]
    if len(t):
        r = v[t] / w[t]
        c1, s1 = kin.libm_cos_sin(yaw[t] + dyaw[t])
        c0, s0 = kin.libm_cos_sin(yaw[t])
        xo[t] = x[t] + r * (s1 - s0)
        yo[t] = y[t] - r * (c1 - c0)
    return xo, yo, np.remainder(yaw + dyaw + math.pi, _TWO_PI) - math.pi


def _turn_back(kept: np.ndarray, yaw: np.ndarray, cos: np.ndarray, sin: np.ndarray, rz: np.ndarray | None) -> None:
    """The moves ``kept`` (their turns cut short by contact) take the heading ``yaw`` they kept:
    their cos, sin (and Rz) rows, as the single simulation's pose of it."""
    c, s = kin.libm_cos_sin(np.ascontiguousarray(yaw, dtype=np.float64))
    cos[kept], sin[kept] = c, s
    if rz is not None:
        rz[kept, 0, 0], rz[kept, 0, 1], rz[kept, 1, 0], rz[kept, 1, 1] = c, -s, s, c
