"""Webots' ``saveState``/``loadState``: a node's state kept under a name, put back on demand (sans-IO).

A node's state is what Webots' ``WbNode::save(id)`` keeps of the node and everything inside it, as
far as Sensorium has it: the pose of a robot or top-level solid (a node inside one moves only with
its joints; a robot riding it: its place on it), and the position of each joint in it (the joint motors' and a drive's wheels' and
steering's, a car's free wheels' too). Loading a state puts each back: the pose bit for bit (a driven robot stops there, its
GPS and radar speeds start over as after a jump), each joint at its saved position with its motor
holding it there at ``maxVelocity`` with its full torque/force (WbMotor::reset, then
WbJoint::setPosition), and the LEDs inside off (WbLed::reset). The clock keeps running.

``"__init__"`` is every node's state as the world loaded (an imported solid's: as imported) until a
Supervisor saves another under that name for that node. At most :data:`MAX_STATES` names are kept
per node (overwriting one is always allowed).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sensorium.server.world.geometry import Pose

INIT = "__init__"
MAX_STATES = 64
"""Saved state names per node (``__init__`` and overwritten names included in the count)."""


@dataclass(frozen=True, slots=True)
class Scope:
    """What of the simulation a node's state covers."""

    what: str                     # the node, for error lines: ``robot 'rover'``, ``HingeJoint 'SHOULDER'``
    robot: str | None = None      # the robot it is or is inside (None: a top-level solid or inside one)
    solid: str | None = None      # the top-level solid it is (its pose is the state's)
    own_pose: bool = False        # the robot's pose is the state's (the node is the robot)
    motors: tuple[str, ...] = ()  # the robot's motors inside the node (joint motors, wheels, steering)
    leds: tuple[str, ...] = ()    # the robot's LEDs inside the node


@dataclass(frozen=True, slots=True)
class State:
    pose: Pose | None             # the robot's or solid's (None: the node has none of its own)
    positions: tuple[float, ...]  # the joints' positions, in the scope's motor order
    free_wheels: dict[str | int, float] | None = None  # free wheels' rolled angles: a car's by key, a tricycle's by index
    riders: dict[str, Pose] | None = None   # the robots riding it: each one's frame on it (fields below the node)
    markers: dict[str, Pose] | None = None  # the shapes a Supervisor imported into its children: each one's frame


class States:
    """The states saved so far, per node id."""

    def __init__(self, limit: int = MAX_STATES):
        self.limit = limit
        self._saved: dict[int, dict[str, State]] = {}

    def names(self, node: int) -> list[str]:
        return [INIT, *(n for n in self._saved.get(node, {}) if n != INIT)]

    def save(self, sim: Any, node: int, scope: Scope, name: str) -> None:
        saved = self._saved.setdefault(node, {})
        if name not in saved and len(saved) >= self.limit:
            raise ValueError(f"{scope.what} already has {self.limit} saved states, the most kept per node "
                             f"here: save under one of its names again ({', '.join(list(saved)[:8])}, ...)")
        saved[name] = _now(sim, scope)

    def load(self, sim: Any, node: int, scope: Scope, name: str) -> None:
        state = self._saved.get(node, {}).get(name)
        if state is None:
            if name != INIT:
                shown = name if len(name) <= 64 else name[:64] + "..."
                raise ValueError(f"{scope.what} has no saved state {shown!r} (saved: "
                                 f"{', '.join(repr(n) for n in self.names(node)[:16])})")
            state = _initial(sim, scope)
        _restore(sim, scope, state)


def _now(sim: Any, scope: Scope) -> State:
    pose = None
    if scope.solid is not None:
        pose = sim.scene.solid_poses[scope.solid]
    elif scope.own_pose:
        robot = sim.robots[scope.robot]
        drive = robot.drive
        # a driven robot on a slope: its own pose (the ground's attitude is applied again on loading); a robot
        # riding another: its frame on its carrier (its fields')
        frame = _rider_frame(sim, robot)
        pose = drive.own_pose() if drive is not None and drive.slope is not None else \
            robot.pose if frame is None else frame
    motors = sim.robots[scope.robot].motors if scope.robot is not None else {}
    turned = _free_turned(sim, scope)
    return State(pose, tuple(float(motors[m].position) for m in scope.motors),
                 dict(turned) if turned is not None else None, _riders(sim, scope, loaded=False),
                 _markers(sim, scope, loaded=False))


def _initial(sim: Any, scope: Scope) -> State:
    pose = None
    if scope.solid is not None:
        pose = sim.initial_solid_pose(scope.solid)
    elif scope.own_pose:
        frame = _rider_frame(sim, sim.robots[scope.robot], loaded=True)
        pose = sim.robots[scope.robot].initial_pose if frame is None else frame
    motors = sim.robots[scope.robot].motors if scope.robot is not None else {}
    turned = _free_turned(sim, scope)
    # a joint motor's initial position is the world file's; a wheel's angle starts at 0
    return State(pose, tuple(float(motors[m].initial_position) for m in scope.motors),
                 dict.fromkeys(turned, 0.0) if turned is not None else None, _riders(sim, scope, loaded=True),
                 _markers(sim, scope, loaded=True))


def _restore(sim: Any, scope: Scope, state: State) -> None:
    if scope.solid is not None and state.pose is not None:
        sim.place_solid(scope.solid, state.pose)
    if scope.robot is None:
        return
    robot = sim.robots[scope.robot]
    for name, position in zip(scope.motors, state.positions):
        robot.motors[name].restore(position)
    sim.joints_moved(robot)
    if state.free_wheels is not None:
        robot.drive.free_turned = dict(state.free_wheels)
    if scope.own_pose and state.pose is not None:
        pose = state.pose
        if robot.drive is not None:
            robot.drive.reset(pose)
            pose = robot.drive.placed(pose)
        if _rider_frame(sim, robot) is not None:
            sim.set_rider_frame(robot, pose)
        else:
            sim.place_robot(robot, pose)
        for dev in robot.devices.values():
            if dev.kind in ("GPS", "Radar"):       # no previous position: the next speeds are NaN
                dev.restart()
        for name, frame in (state.riders or {}).items():
            sim.set_rider_frame(sim.robots[name], frame)
        for name, frame in (state.markers or {}).items():
            ride = sim.solid_riders.get(name)
            if ride is not None and ride[0] is robot:       # (removed since: gone)
                sim.ride_solid(name, scope.robot, frame)
    for name in scope.leds:
        led = robot.devices.get(name)
        if led is not None and led.value != 0:
            led.set(0, sim.time_ms)


def _riders(sim: Any, scope: Scope, loaded: bool) -> dict[str, Pose] | None:
    """A robot's riders' frames on it (``loaded``: as the world file put them): Webots' state of a node covers
    the fields of the nodes below it, a rider's translation and rotation among them."""
    if not scope.own_pose:
        return None
    return {r.name: sim.rider_frame(r, loaded) for r in sim.riders_of(sim.robots[scope.robot])} or None


def _markers(sim: Any, scope: Scope, loaded: bool) -> dict[str, Pose] | None:
    """The frames on a robot of the shapes a Supervisor imported into its children (``loaded``: as imported):
    their translation and rotation are fields below it, in its state as a rider's are."""
    riders = sim.solid_riders
    if not scope.own_pose or not riders:
        return None
    robot = sim.robots[scope.robot]
    return {name: sim.initial_solid_pose(name) if loaded else frame
            for name, (carrier, frame) in riders.items() if carrier is robot} or None


def _rider_frame(sim: Any, robot: Any, loaded: bool = False) -> Any:
    """A robot riding another: its frame on its carrier (Simulation.rider_frame); None otherwise."""
    return sim.rider_frame(robot, loaded)


def _free_turned(sim: Any, scope: Scope) -> dict[str | int, float] | None:
    """The rolled angles of the free wheels of the robot the node is (PlanarState.free_turned); None for any
    other node, and for a robot whose drive has none."""
    drive = sim.robots[scope.robot].drive if scope.own_pose else None
    return None if drive is None else drive.free_turned
