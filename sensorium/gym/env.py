"""``SensoriumEnv``: a Gymnasium environment over the in-process simulation.

    env = SensoriumEnv("sensorium/worlds/arena.yaml", Task(robot="epuck", reward=ReachLight(), ...))
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

Observation: a ``Dict`` with one ``Box`` per observed sensor (LEDs are not observations). A light
or distance sensor is a float32 ``(1,)`` box bounded by its lookup table's output column (values are clipped into it:
relative lookup noise is Gaussian and could leave it); a lidar is its float32 ``(layers,
width)`` range image bounded by ``[0, max_range]``, with "no hit" (``inf`` in Webots) given as
``max_range``; a position sensor (wheel encoder) is an unbounded ``(1,)`` box in radians; a GPS its
position, a compass its north vector, an inertial unit its roll, pitch, yaw, a gyro its angular
velocity, an accelerometer its specific force: float32 ``(3,)`` boxes (:func:`_space`; a disabled
axis's NaN reads the box's low bound, as any missing value); a bumper (TouchSensor) a float32 ``(1,)``
box in [0, 1] (1 when it touched something since its last reading), an altimeter its height, a float32
``(1,)`` box within the world bounds (a force TouchSensor reads NaN without physics: left out by
default, refused when named); a camera
(only when named in ``Task.observations``: images are not observed by default) is a uint8
``(height, width, 3)`` RGB box, a range finder (likewise) its float32 ``(height, width)`` range image
in ``[0, max_range]`` with "no hit" as ``max_range``; ``"<camera>/segmentation"`` (named, of a camera
whose Recognition node has ``segmentation: true``) its segmentation image, a uint8 ``(height, width, 3)``
RGB box (recognition and segmentation enabled at the observation's period; black before the first).
``flatten=True``: one float32 ``Box`` instead, the Dict's boxes flattened and concatenated in its
(sorted) key order, as ``gymnasium.wrappers.FlattenObservation`` gives.

Action: float32 ``(2,)`` = left, right wheel (every wheel of its side, for a skid-steer robot).
``actions="normalized"`` (the default): in ``[-1, 1]``, each times its own wheel's maxVelocity (rad/s:
``max_wheel_speed``, or the wheel motor's ``motor_max_speeds`` entry; an Elisa-3's +1 is 133.33 rad/s
left, 140 right) -- the symmetric, normalised box training libraries and Gymnasium's checker recommend;
``actions="wheel"``: the wheel velocities themselves (rad/s), each bounded by its wheel's maximum.
Either way a velocity beyond the maximum is clamped, as Webots does. One action lasts
``control_period_ms``.

A car-like robot (``ackermann_drive``) acts with float32 ``(2,)`` = steering, speed. Normalised:
steering in ``[-1, 1]`` times ``max_steering_angle``, **+1 turning left** (counter-clockwise seen from
above, as ROS's REP 103, whatever the motors' ``positive_steers``), speed in ``[-1, 1]`` times
the driven wheels' smallest maxVelocity for every driven wheel (+1 forward, all alike); ``actions="wheel"``: the steering angle
(rad, positive left, beyond ``±max_steering_angle`` the limit) and the wheels' velocity (rad/s).
The steering angle is the bicycle model's: the two steering motors are set to Webots' Driver's
Ackermann angles for it (``cot δ_inner = cot δ - track_front/2L``, outer ``+``), which their
``max_steering_angle`` limit clamps (near full lock the inner wheel stops at the limit), and turn
there at ``max_steering_speed`` (position control), so a new steering takes a few steps to reach.

A mecanum robot (``mecanum_drive``, a youBot's base) acts with float32 ``(4,)`` = its four wheels'
velocities in the drive's order (front left, front right, rear left, rear right): normalised, each in
``[-1, 1]`` times its own wheel's maxVelocity; ``actions="wheel"``: rad/s, bounded by it. All four at +1 drive
forward, and with the default (youBot) rollers (-1, +1, +1, -1) strafes left and (-1, +1, -1, +1)
turns left on the spot (README "mecanum"); the body twist is the wheels' least-squares fit. An
omni-wheel robot (``omni_drive``, three or more omni wheels) acts alike with one velocity per wheel,
float32 ``(n,)`` in the drive's ``wheels`` order: all at +1 turn it in place (clockwise for wheels
whose axes point out from its centre).

``reset(seed=s)`` restarts the world with a world seed drawn from the environment's generator
seeded with ``s``: every device noise stream, the start pose drawn by ``Task.start`` and the clock
restart exactly, so the same seed and actions give a bit-identical episode. ``engine``: where the
world runs -- ``"batched"``: the batched simulation of the vector environment with one copy (a reset
reuses the built scene; ``sim`` is a view of the copy, :mod:`sensorium.gym.views`);
``"simulation"`` (the default): a :class:`Simulation` rebuilt at every reset (every device kind;
``sim`` is it); ``"auto"``: batched when it simulates every observed device and the world, else
simulation. Both engines give the same episodes bit for bit (tested). Measured here: a batched
reset takes 2.6 ms of CPU against 22 ms for a rebuild, but one copy steps at ~60 % of the rate of a
Simulation (383 vs 625 ReachLight steps per CPU second): the batched engine pays off with many
copies (the vector environment), or with many short episodes. Before the first observation the simulation runs until every observed device has a value
(its longest sampling period), as a Webots controller would wait.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sensorium.gym.render import TopDown, TopDownRendering, check_render_size
from sensorium.gym.task import Task, whole
from sensorium.gym.views import CopySim
from sensorium.schemas import world as wm
from sensorium.server.raycast.kinds import Precision
from sensorium.server.sim.frames import drive_forward, enu_axes, planar_pose
from sensorium.server.sim.motion import ackermann_angles
from sensorium.server.sim.sensors import altitude_offset
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import MAX_COORDINATE_M
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world
from sensorium.server.world.report import warn_losses

__all__ = ["SensoriumEnv", "Agent", "load", "rebuild", "DEFAULT_PRECISION"]


def load(world: str | Path | LoadedWorld | wm.World | None) -> LoadedWorld:
    """A world file path, a loaded world or a world model (None: the embedded arena world)."""
    if world is None:
        return load_world(default_world_path())
    if isinstance(world, LoadedWorld):
        return world
    if isinstance(world, wm.World):
        return LoadedWorld(world=world, source="<memory>", base_dir=Path.cwd())
    loaded = load_world(world)
    warn_losses(loaded.report)        # a robot, device or shape the world lost: said once
    return loaded


class Agent:
    """One acting robot: its task, observed devices and periods, observation and action spaces."""

    def __init__(self, loaded: LoadedWorld, task: Task, default_robot: str | None = None,
                 actions: str = "normalized", flatten: bool = False):
        if actions not in ACTION_MODES:
            raise ValueError(f"actions must be one of {', '.join(ACTION_MODES)}, got {actions!r}")
        self.task = task
        self.actions = actions
        w = loaded.world
        self.axes = enu_axes(w)       # the world's east, north, up (info["pose"] is in them)
        basic = w.world_info.basic_time_step
        robots = {r.name: r for r in w.robots}
        name = task.robot or default_robot
        if name is None:
            driven = [r.name for r in w.robots if has_drive(r)]
            if not driven:
                raise ValueError(f"{loaded.source}: no robot with a differential_drive, an ackermann_drive, a "
                                 "mecanum_drive or an omni_drive to act as the agent")
            name = driven[0]
        if name not in robots:
            raise ValueError(f"{loaded.source}: task robot {name!r} not in the world (robots: {', '.join(robots)})")
        model = robots[name]
        if model.steered_drive is not None:     # its steering hinges are joints: no action maps onto them
            raise ValueError(f"{loaded.source}: task robot {name!r} has a steered_drive, which the gym's actions "
                             "(wheel speeds) do not drive: use Simulation")
        if not has_drive(model):
            raise ValueError(f"{loaded.source}: task robot {name!r} has no differential_drive, ackermann_drive, "
                             "mecanum_drive or omni_drive to act with")
        self.robot = name
        self.forward = drive_forward(model)     # its heading's direction in its own frame (None: its x)
        ctrl = basic if task.control_period_ms is None else task.control_period_ms
        if not whole(ctrl) or ctrl <= 0 or ctrl % basic:
            raise ValueError(f"task control_period_ms={ctrl} must be a positive multiple of the world's "
                             f"basic_time_step ({basic} ms)")
        self.control_period_ms = int(ctrl)
        steps = task.max_steps
        if steps is not None and (not whole(steps) or steps < 1):
            raise ValueError(f"task max_steps must be a whole number of actions >= 1, or None (never truncated), "
                             f"got {steps!r}")
        devices = {d.name: d for d in model.devices if d.device in OBSERVABLE}
        actuators = {d.name for d in model.devices if d.device not in OBSERVABLE}
        obs = task.observations
        if obs is None:              # images cost a ray per pixel: observed only when named
            periods = {n: self.control_period_ms for n, d in devices.items()
                       if d.device not in IMAGES and not _without_value(d)}
        elif isinstance(obs, dict):
            periods = {str(k): int(v) for k, v in obs.items()}
        else:
            periods = {str(n): self.control_period_ms for n in obs}
        for n, p in periods.items():
            if n.endswith(SEGMENTATION):
                _check_segmentation(n, name, devices)
                continue
            if n in actuators:
                raise ValueError(f"task observation {n!r}: robot {name!r}'s {n} is not a sensor")
            if n not in devices:
                raise ValueError(f"task observation {n!r}: robot {name!r} has no such device "
                                 f"(sensors: {', '.join(devices) or 'none'})")
            if p <= 0:
                raise ValueError(f"task observation {n!r}: sampling period must be > 0 ms, got {p}")
            if _without_value(devices[n]):
                raise ValueError(f"task observation {n!r}: robot {name!r}'s {n} is a {devices[n].type} TouchSensor, "
                                 "which reads NaN without physics (only a bumper is an observation)")
        self.periods = periods
        self.warmup_steps = max((math.ceil(p / basic) for p in periods.values()), default=0)
        self.dict_space = spaces.Dict({n: _space(devices[device_of(n)], w.world_info) for n in periods})
        self.flatten = bool(flatten)
        self.observation_space: spaces.Space = (spaces.flatten_space(self.dict_space) if self.flatten
                                                else self.dict_space)
        # a car-like robot acts with (steering, speed), a mecanum or omni-wheel one with its wheels: see
        # :meth:`commands`
        self.car: wm.AckermannDrive | None = model.ackermann_drive
        self.mecanum: wm.MecanumDrive | None = model.mecanum_drive
        self.omni: wm.OmniDrive | None = model.omni_drive
        holonomic = self.mecanum or self.omni
        self.wheel_motors: list[str] | None = (None if holonomic is None
                                               else [name for _, name in holonomic.motor_fields])
        """A mecanum or omni-wheel robot's wheel motors, in the order of its action; None for the others."""
        self.n_actions = 2 if self.wheel_motors is None else len(self.wheel_motors)
        """The action's length: 2 (left, right or steering, speed), a mecanum or omni-wheel robot's wheels."""
        if self.car is None:
            drive = model.differential_drive or holonomic
            assert drive is not None
            two = model.differential_drive
            motors = [two.left_motor, two.right_motor] if two is not None else self.wheel_motors or []
            # each action's own wheel's maxVelocity (a skid-steer side's wheels share theirs)
            self.vmax: Any = (vmax := np.array([wm.wheel_max_speed(drive, m) for m in motors]))
            raw = spaces.Box(-vmax.astype(np.float32), vmax.astype(np.float32), dtype=np.float32)
        else:
            # one speed for every driven wheel: the slowest one's maximum, so +1 turns them all alike
            self.vmax = min(wm.wheel_max_speed(self.car, m) for _, m in self.car.driven)
            self.max_steer = float(self.car.max_steering_angle)
            self.scale = np.array([self.max_steer, self.vmax])
            raw = spaces.Box(-self.scale.astype(np.float32), self.scale.astype(np.float32), dtype=np.float32)
        self.action_space = (spaces.Box(-1.0, 1.0, shape=(self.n_actions,), dtype=np.float32)
                             if actions == "normalized" else raw)

    def start(self, sim: Simulation, rng: np.random.Generator) -> None:
        """After a rebuild: start pose, wheels at rest in velocity control, devices enabled."""
        robot = sim.robot(self.robot)
        if self.task.start is not None:
            self.task.start(sim, robot, rng)
        # (a car's steering motors stay as built: position control at 0, at max_steering_speed)
        wheels = (robot.motors.values() if self.car is None and self.wheel_motors is None
                  else [robot.motors[n] for n in ([n for _, n in self.car.driven] if self.car is not None
                                                  else self.wheel_motors or [])])
        for m in wheels:
            m.set_position(math.inf)
            m.set_velocity(0.0)
        for n, p in self.periods.items():
            if n.endswith(SEGMENTATION):
                cam = robot.device(device_of(n))
                cam.recognition_enable(p)
                cam.enable_segmentation(True)
            else:
                robot.device(n).enable(p)

    def reset_callables(self, sim: Simulation) -> None:
        robot = sim.robot(self.robot)
        owners: list = []
        for fn in (self.task.reward, self.task.terminated):
            owner = fn if hasattr(fn, "reset") else getattr(fn, "__self__", None)
            if owner is not None and hasattr(owner, "reset") and not any(o is owner for o in owners):
                owners.append(owner)
                owner.reset(sim, robot)

    def commands(self, action) -> np.ndarray:
        """An action -> float64 (2,): (left, right) wheel velocities (rad/s), or a car's (steering
        angle (rad, positive left), driven wheels' velocity (rad/s)); a mecanum robot's (4,) or an
        omni-wheel robot's (n,) wheel velocities (rad/s, the drive's order); clamped later by the motors."""
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (self.n_actions,) or not np.all(np.isfinite(a)):
            what = ("values (in [-1, 1]: beyond it, clipped)" if self.actions == "normalized"
                    else "wheel velocities" if self.car is None else "values (rad, rad/s)")
            names = ("steering, speed" if self.car is not None
                     else "front left, front right, rear left, rear right" if self.mecanum is not None
                     else ", ".join(self.wheel_motors) if self.wheel_motors is not None
                     else "left, right")
            # (the values as a list: an array's repr would break the line)
            raise ValueError(f"{self.robot}: action must be {self.n_actions} finite {what} ({names}), "
                             f"got {a.tolist()!r}")
        return self.scaled(a)

    def scaled(self, a: np.ndarray) -> np.ndarray:
        """Finite float64 actions (..., n_actions) -> the commands of :meth:`commands`, row by row (the vector
        env's actions of every sub-env at once)."""
        # a normalized action beyond [-1, 1] asks for more than the wheels give: clipped before the
        # scaling, which is the motors' clamp for any finite value (1e308 * vmax would overflow to inf)
        if self.car is None:
            return np.clip(a, -1.0, 1.0) * self.vmax if self.actions == "normalized" else a
        if self.actions == "normalized":
            return np.clip(a, -1.0, 1.0) * self.scale
        # (a steering angle beyond the limit is the limit: tan of a huge angle would steer anywhere)
        out = a.copy()
        out[..., 0] = np.minimum(np.maximum(a[..., 0], -self.max_steer), self.max_steer)
        return out

    def steering_positions(self, angle: float) -> tuple[float, float]:
        """A car's steering motors' positions (right, left) for a steering angle (rad, positive
        left): Webots' Driver's Ackermann angles (motion.ackermann_angles takes positive right),
        in the motors' sense (``positive_steers``); the motors clamp them to ±max_steering_angle."""
        car = self.car
        assert car is not None
        right, left = ackermann_angles(-angle, float(car.wheelbase), float(car.track_front))
        sign = 1.0 if car.positive_steers == "right" else -1.0
        return sign * right, sign * left

    def act(self, sim: Simulation, action) -> None:
        v = self.commands(action)
        robot = sim.robot(self.robot)
        if self.car is not None:
            right, left = self.steering_positions(float(v[0]))
            robot.motors[self.car.right_steer].set_position(right)
            robot.motors[self.car.left_steer].set_position(left)
            for _, name in self.car.driven:
                robot.motors[name].set_velocity(float(v[1]))
            return
        if self.wheel_motors is not None:
            for name, u in zip(self.wheel_motors, v.tolist()):
                robot.motors[name].set_velocity(u)
            return
        drive = robot.drive
        # every wheel of a side (a skid-steer robot has several); a side mounted mirrored (reversed_motors) is
        # commanded negated: an action's left and right are the sides' forward rolling speeds
        for m in drive.lefts:
            m.set_velocity(drive.left_sign * float(v[0]))
        for m in drive.rights:
            m.set_velocity(drive.right_sign * float(v[1]))

    def observe(self, sim: Simulation):
        robot = sim.robot(self.robot)
        out = {}
        for n, box in self.dict_space.spaces.items():
            dev = robot.device(device_of(n))
            if n.endswith(SEGMENTATION):                   # BGRA -> RGB
                out[n] = np.ascontiguousarray(dev.segmentation_image[:, :, 2::-1])
            elif dev.kind == "Camera":                     # BGRA -> RGB
                out[n] = np.ascontiguousarray(dev.image[:, :, 2::-1])
            elif dev.kind in ("Lidar", "RangeFinder"):
                img = np.nan_to_num(dev.range_image, nan=box.high.flat[0], posinf=box.high.flat[0])
                out[n] = np.clip(img, box.low, box.high).astype(np.float32)
            elif dev.kind in VECTOR_READINGS:              # (3,): a missing value (a disabled axis) as a scalar's
                v = np.asarray(getattr(dev, VECTOR_READINGS[dev.kind]), dtype=np.float64)
                out[n] = np.clip(np.where(np.isfinite(v), v, missing_fill(box.low)).astype(np.float32), box.low,
                                 box.high)
            else:
                v = dev.value if math.isfinite(dev.value) else (box.low[0] if np.isfinite(box.low[0]) else 0.0)
                out[n] = np.clip(np.array([v], dtype=np.float32), box.low, box.high)
        return spaces.flatten(self.dict_space, out) if self.flatten else out

    def outcome(self, sim: Simulation, obs: dict, steps: int) -> tuple[float, bool, bool]:
        robot = sim.robot(self.robot)
        reward = float(self.task.reward(sim, robot, obs))
        terminated = bool(self.task.terminated(sim, robot, obs))
        truncated = self.task.max_steps is not None and steps >= self.task.max_steps and not terminated
        return reward, terminated, bool(truncated)

    def info(self, sim: Simulation, steps: int) -> dict[str, Any]:
        """``time_ms``, ``steps`` and ``pose``: the robot's (east, north, yaw) in the world's ENU view
        (:mod:`sensorium.server.sim.frames`; in an ENU world its x, y and heading about z), the yaw its
        drive's forward's."""
        pose = sim.robot(self.robot).pose
        return {"time_ms": sim.time_ms, "steps": steps,
                "pose": np.array(planar_pose(self.axes, pose.translation, pose.rotation, self.forward))}


def has_drive(model: wm.Robot) -> bool:
    """Whether a robot can act as an agent: it has a two-wheel (or skid-steer), car-like, mecanum or
    omni-wheel drive."""
    return (model.differential_drive is not None or model.ackermann_drive is not None
            or model.mecanum_drive is not None or model.omni_drive is not None)


OBSERVABLE = ("LightSensor", "DistanceSensor", "Lidar", "PositionSensor", "GPS", "Compass", "InertialUnit",
              "Gyro", "Accelerometer", "TouchSensor", "Altimeter", "Camera", "RangeFinder")
IMAGES = ("Camera", "RangeFinder")
SEGMENTATION = "/segmentation"     # "<camera>/segmentation": the camera's segmentation image observed


def device_of(observation: str) -> str:
    """The device an observation name reads (a camera's for ``"<camera>/segmentation"``)."""
    return observation.removesuffix(SEGMENTATION)


def _check_segmentation(observation: str, robot: str, devices: dict) -> None:
    cam = devices.get(device_of(observation))
    if cam is None or cam.device != "Camera":
        raise ValueError(f"task observation {observation!r}: robot {robot!r} has no camera "
                         f"{device_of(observation)!r} (sensors: {', '.join(devices) or 'none'})")
    if cam.recognition is None or not cam.recognition.segmentation:
        raise ValueError(f"task observation {observation!r}: camera {cam.name!r} has no Recognition node with "
                         "segmentation: true")
VECTOR_READINGS = {"GPS": "values", "Compass": "values", "InertialUnit": "roll_pitch_yaw", "Gyro": "values",
                   "Accelerometer": "values"}
"""The kinds observed as a float32 ``(3,)`` box, and the device reading each observes (a GPS its
position, a compass its north vector, an inertial unit its roll, pitch, yaw, a gyro its angular
velocity, an accelerometer its specific force)."""


def _without_value(cfg) -> bool:
    """A device whose reading is never a value here: a force or force-3d TouchSensor (NaN without
    physics; a bumper is observed)."""
    return cfg.device == "TouchSensor" and cfg.type != "bumper"


def missing_fill(low: np.ndarray) -> np.ndarray:
    """What an observation reads for a missing value (NaN: no value yet, a disabled axis): its box's
    low bound where that is finite, else 0 (float64, per entry)."""
    return np.where(np.isfinite(low), np.asarray(low, dtype=np.float64), 0.0)

DEFAULT_PRECISION = "fast"
"""The Gymnasium environments' default ray precision (single, vector and PettingZoo alike, so the
same seed gives the same episode in all of them). EXACT's float64 refinement cost 27-40 % of
ReachLight's and 44-51 % of LidarAvoid's batched env steps/s (``sensorium bench --only training``),
while what FAST changes is small: over 16 x 150 random-action steps the ReachLight observations
were identical, and 0.4 % of LidarAvoid's lidar ranges differed by more than 1 mm (beams grazing
edges, where float32 traversal can slip between triangles; 45 % differed by float32 rounding,
< 1e-5 m). Pass ``precision="exact"`` for Webots-exact rays."""
ACTION_MODES = ("normalized", "wheel")


def motion_bound(device: str, world_info: wm.WorldInfo) -> float:
    """The largest magnitude a Gyro or an Accelerometer without a lookup table reads on an axis
    (devices/motion_sensors.py): a gyro turns at most half a turn in a basic step ``dt``, so
    ``π / dt`` rad/s; an accelerometer reads the second difference of positions within the world's
    coordinate limits (±MAX_COORDINATE_M on each axis: ``|a| <= 4·√3·M / dt²``) plus gravity."""
    dt = world_info.basic_time_step / 1000.0
    if device == "Gyro":
        return math.pi / dt
    return 4.0 * math.sqrt(3.0) * MAX_COORDINATE_M / (dt * dt) + float(world_info.gravity)


def _space(cfg, world_info: wm.WorldInfo) -> spaces.Box:
    if cfg.device == "PositionSensor":          # a wheel angle (rad): unbounded
        return spaces.Box(-np.inf, np.inf, shape=(1,), dtype=np.float32)
    if cfg.device == "GPS":                     # a position within the world bounds about gps_reference
        ref = np.asarray(world_info.gps_reference, dtype=np.float64)
        low, high = ref - MAX_COORDINATE_M, ref + MAX_COORDINATE_M
        if world_info.gps_coordinate_system == "WGS84":          # latitude, longitude (degrees), altitude
            # longitudes are not wrapped (as in Webots): east of the antimeridian they pass 180
            low[:2], high[:2] = (-90.0, -360.0), (90.0, 360.0)
        return spaces.Box(low.astype(np.float32), high.astype(np.float32), dtype=np.float32)
    if cfg.device == "InertialUnit":            # roll, pitch, yaw (rad)
        half = np.float32(math.pi / 2)
        pi = np.float32(math.pi)
        return spaces.Box(np.array([-pi, -half, -pi], dtype=np.float32), np.array([pi, half, pi], dtype=np.float32),
                          dtype=np.float32)
    if cfg.device == "Compass":                 # north through the lookup table (none: the unit vector)
        return _table_box(cfg, (3,), (-1.0, 1.0))
    if cfg.device in ("Gyro", "Accelerometer"):   # through the lookup table (none: what the motion can give)
        bound = motion_bound(cfg.device, world_info)
        return _table_box(cfg, (3,), (-bound, bound))
    if cfg.device == "TouchSensor":             # a bumper: 1 when it touched since its last reading, else 0
        return spaces.Box(np.float32(0.0), np.float32(1.0), shape=(1,), dtype=np.float32)
    if cfg.device == "Altimeter":               # a height within the world bounds (+ the reference altitude)
        offset = altitude_offset(world_info)
        return spaces.Box(np.float32(offset - MAX_COORDINATE_M), np.float32(offset + MAX_COORDINATE_M), shape=(1,),
                          dtype=np.float32)
    if cfg.device == "Camera":
        return spaces.Box(0, 255, shape=(cfg.height, cfg.width, 3), dtype=np.uint8)
    if cfg.device == "RangeFinder":
        return spaces.Box(0.0, np.float32(cfg.max_range), shape=(cfg.height, cfg.width), dtype=np.float32)
    if cfg.device == "Lidar":
        return spaces.Box(0.0, np.float32(cfg.max_range), shape=(cfg.number_of_layers, cfg.horizontal_resolution),
                          dtype=np.float32)
    return _table_box(cfg, (1,), (0.0, 0.0))


def _table_box(cfg, shape: tuple[int, ...], without: tuple[float, float]) -> spaces.Box:
    """A float32 Box bounded by the device's lookup table's output column (``without``: the bounds
    when it has no table)."""
    out = [row[1] for row in cfg.lookup_table]
    low, high = (min(out), max(out)) if out else without
    return spaces.Box(np.float32(low), np.float32(high), shape=shape, dtype=np.float32)


ENGINES = ("auto", "batched", "simulation")


def check_precision(value) -> str:
    """``precision`` as "fast" or "exact"; a ValueError naming it otherwise (the single env builds its
    simulation at reset, so it is checked when the env is made)."""
    choices = [p.value for p in Precision]
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"precision must be one of {', '.join(choices)}, got {value!r}")
    return value


def batched_engine(loaded: LoadedWorld, agents: list[Agent], precision: str, engine: str):
    """The one-copy batched simulation the environments run on (``engine`` "batched", or "auto"
    when it simulates the world and every observed device), None for a rebuilt Simulation."""
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation, check_observable

    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    if engine == "simulation":
        return None
    try:
        for ag in agents:              # e.g. an observed GPS in a WGS84 world: nothing built
            check_observable(loaded.world, ag.robot, map(device_of, ag.periods))
        sim = BatchedSimulation(loaded, 1, precision=precision)
        for ag in agents:
            for name in ag.periods:
                sim.check_observable(ag.robot, device_of(name))
    except BatchedError:
        if engine == "batched":
            raise
        return None
    return sim


def rebuild(loaded: LoadedWorld, world_seed: int, precision: str) -> Simulation:
    """A fresh simulation of ``loaded`` with ``world_seed``: clock, poses, motors, device state and
    noise streams all as at the start."""
    w = loaded.world
    w = w.model_copy(update={"world_info": w.world_info.model_copy(update={"random_seed": world_seed})})
    return Simulation(LoadedWorld(world=w, source=loaded.source, base_dir=loaded.base_dir, text=loaded.text,
                                  textures=loaded.textures),
                      precision=precision)


class SensoriumEnv(TopDownRendering, gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, world: str | Path | LoadedWorld | wm.World | None = None, task: Task | None = None,
                 render_mode: str | None = None, precision: str = DEFAULT_PRECISION, render_size: int = 256,
                 actions: str = "normalized", flatten: bool = False, engine: str = "simulation"):
        self.loaded = load(world)
        self.task = task or Task()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.render_mode = render_mode
        self.precision = precision = check_precision(precision)
        self.render_size = check_render_size(render_size)
        self.basic_time_step = self.loaded.world.world_info.basic_time_step
        self.agent = Agent(self.loaded, self.task, actions=actions, flatten=flatten)
        self.robot_name = self.agent.robot
        self.control_period_ms = self.agent.control_period_ms
        self.steps_per_action = self.control_period_ms // self.basic_time_step
        self.periods = self.agent.periods
        self.observation_space = self.agent.observation_space
        self.action_space = self.agent.action_space
        self.sim: Any = None
        self._batched = batched_engine(self.loaded, [self.agent], precision, engine)
        self.engine = "batched" if self._batched is not None else "simulation"
        self.steps = 0
        self._renderer: TopDown | None = None

    # ---------------------------------------------------------------- gymnasium API
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        world_seed = int(self.np_random.integers(0, 2**62))
        if self._batched is not None:           # the built scene, the copy as new: nothing rebuilt
            self._batched.reset([0], [world_seed])
            self.sim = sim = CopySim(self._batched, 0)
        else:
            self.sim = sim = rebuild(self.loaded, world_seed, self.precision)
        self.agent.start(sim, self.np_random)
        # run until every observed device has measured once (Webots: first value one period later)
        sim.run(self.agent.warmup_steps)
        self.steps = 0
        self.agent.reset_callables(sim)
        self._renderer = None
        return self.agent.observe(sim), self.agent.info(sim, 0)

    def step(self, action):
        if self.sim is None:
            raise RuntimeError("call reset() before step()")
        self.agent.act(self.sim, action)
        self.sim.run(self.steps_per_action)
        self.steps += 1
        obs = self.agent.observe(self.sim)
        reward, terminated, truncated = self.agent.outcome(self.sim, obs, self.steps)
        return obs, reward, terminated, truncated, self.agent.info(self.sim, self.steps)
