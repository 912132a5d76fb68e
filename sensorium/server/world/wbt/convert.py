"""Parsed .wbt tree → a Sensorium world (a plain dict in the world-file format, then validated).

Flattening happens here: Pose/Transform/Group frames are composed into the poses of shapes,
devices and lights; a top-level Solid becomes a world solid, a Solid inside it one of its
``children``; everything inside a Robot (nested Solids, joint end points, device bodies) becomes a
body shape or a device of the robot, placed relative to the robot. Two motorised HingeJoint wheels
on one axle become the robot's kinematic ``differential_drive``; steered front wheels (vertical
hinges or Hinge2Joints) and driven wheels its ``ackermann_drive``; four wheels whose friction a
ContactProperties turns (mecanum rollers, a youBot) its ``mecanum_drive`` (wbt/drive.py). Any other
motorised HingeJoint or SliderJoint keeps its axis (and anchor) in the robot's frame on its motor,
and what its end point holds names that motor in ``on_joint`` (it moves with the joint).

Poses keep the file's exact axis-angle values when only one level rotates (so a converted world
reads bit for bit like its hand-written twin); a pose composed of several rotations is written as
a quaternion.
"""

from __future__ import annotations

import itertools
import math
import posixpath
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world import geometry as geo
from sensorium.server.world.cad import EAR_CLIP_CORNERS, ear_clip, reflex_corners
from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion
from sensorium.server.world.report import Loss
from sensorium.server.world.wbt import fields as fx
from sensorium.server.world.wbt.drive import UP_Z, Up
from sensorium.server.world.wbt.fields import Fields
from sensorium.server.world.wbt.frames import Frame, bounding_constraint, bounding_geometry, visual_geometry
from sensorium.server.world.wbt.inside import enclosing_shapes, turn_meshes_away, unread_image_fields
from sensorium.server.world.wbt.mass import solid_mass
from sensorium.server.world.wbt.parser import Node, WbtFile, WbtSyntaxError
from sensorium.server.world.wbt.protos import BUILTIN_FIELDS, BUILTIN_PROTOS

MAX_PARTS = 200_000     # shapes, devices and lights after DEF/USE expansion
MAX_VISITS = 2_000_000  # nodes walked after DEF/USE expansion (empty groups USEd over and over)

# the fields of top-level nodes not simulated whose written values the Supervisor serves (daemon/supervisor.py)
SCENERY_VALUES = {
    "Viewpoint": {"fieldOfView": "SFFloat", "orientation": "SFRotation", "position": "SFVec3f", "near": "SFFloat",
                  "far": "SFFloat", "exposure": "SFFloat", "description": "SFString", "follow": "SFString",
                  "followType": "SFString", "followSmoothness": "SFFloat"},
    "Background": {"skyColor": "MFColor", "luminosity": "SFFloat"},
    # a top-level Pose or Transform holding solids (world/top_nodes.py): a Supervisor reads where it is
    "Pose": {"translation": "SFVec3f", "rotation": "SFRotation"},
    "Transform": {"translation": "SFVec3f", "rotation": "SFRotation", "scale": "SFVec3f"},
}
# the base node type of Webots' PROTOs that Sensorium builds in (wbt/protos.py) or skips (TexturedBackground)
# when their file is not at hand: the Supervisor names them as Webots does
KNOWN_PROTO_BASES = {"RectangleArena": "Solid", "Floor": "Solid", "SolidBox": "Solid", "WoodenBox": "Solid",
                     "CircleArena": "Solid", "SolidPipe": "Solid",
                     "TexturedBackgroundLight": "DirectionalLight", "TexturedBackground": "Background"}
SKIPPED = {"Background", "TexturedBackground", "Physics", "ImmersionProperties",
           "ContactProperties", "Damping", "Muscle"}
# devices not simulated here: listed in the robot's devices (Webots' indices) as UnsimulatedDevice;
# the Solid ones keep their shapes as part of the robot's body (Charger and Track are Solids, not devices)
OTHER_DEVICES = {"Display", "Speaker", "Microphone", "Emitter", "Receiver", "GPS",
                 "Compass", "Accelerometer", "Gyro", "InertialUnit", "TouchSensor", "Pen", "Charger",
                 "Connector", "Radar", "Altimeter", "VacuumGripper", "Radio", "Track", "Skin"}
# Webots' default device names (the ``name`` field's default of each node)
OTHER_NAMES = {"RangeFinder": "range-finder", "InertialUnit": "inertial unit", "TouchSensor": "touch sensor",
               "VacuumGripper": "vacuum gripper", "LinearMotor": "linear motor", "GPS": "gps"}
GEOMETRIES = {"Box", "Sphere", "Cylinder", "Capsule", "Cone", "Plane", "IndexedFaceSet", "Mesh", "ElevationGrid"}
MAX_GRID_POINTS = 4_000_000    # ElevationGrid points (xDimension × yDimension, all grids together after DEF/USE:
                               # ProtoLimits.values), checked before a height is read or padded
# what a Billboard may hold without losing anything a device reads (it follows the 3D view, no Camera sees it)
BILLBOARD_CONTENT = {"Shape", "Transform", "Pose", "Group", "Appearance", "PBRAppearance", "Material",
                     "ImageTexture", "TextureTransform", "Coordinate", "Normal", "TextureCoordinate", "Color",
                     "IndexedLineSet", "PointSet"} | GEOMETRIES
UNSEEN_GEOMETRIES = {"IndexedLineSet", "PointSet"}      # lines and points: no surface a ray could hit
LIGHTS = {"PointLight", "SpotLight", "DirectionalLight"}
SENSORS = {"DistanceSensor", "LightSensor", "Lidar", "PositionSensor", "LED", "RangeFinder", "Camera"}
JOINTS = {"HingeJoint", "Hinge2Joint", "SliderJoint", "BallJoint"}
# a Robot inside a robot holding only these (shapes and solids) and no controller rides it as part of its body
PLAIN_ROBOT_CONTENT = {"Pose", "Transform", "Group", "Shape", "CadShape", "Solid", "Slot"}
# a Background's cube maps: Webots' renderer lights PBR shapes by them (image-based lighting)
BACKGROUND_MAPS = tuple(f"{side}{kind}Url" for side in ("back", "bottom", "front", "left", "right", "top")
                        for kind in ("", "Irradiance"))
MOTORS = {"RotationalMotor", "LinearMotor"}
OTHER_MOTOR_NAMES = {"RotationalMotor": "rotational motor", "LinearMotor": "linear motor"}
JOINT_KEYS = ("max_velocity", "min_position", "max_position", "acceleration", "max_torque", "position", "axis",
              "anchor", "multiplier")
MANY_JOINTS = 4      # more motorised joints than this, none a wheel: one warning for the robot, naming the first few
JOINT_MOVES = ("its joint moves kinematically (Webots' rule without physics; its PositionSensor reads it), and "
               "the shapes and devices past the joint with it")
# the same for a joint ending in a SolidReference (a linkage's loop-closing joint, driven: the Khepera III
# gripper's fingers): nothing is past it here, as the loop is not closed
JOINT_MOVES_NOTHING = ("its joint moves kinematically (Webots' rule without physics; its PositionSensor reads it), "
                       "but moves nothing: its end point is SolidReference {name!r}, whose loop is not closed here")
JOINT_MOVES_NO_SOLID = ("its joint moves kinematically (Webots' rule without physics; its PositionSensor reads it), "
                        "but moves nothing: its end point is SolidReference {name!r}, which names no Solid")
# the fields every Solid has (a device's own fields are the others)
SOLID_FIELDS = {"translation", "rotation", "children", "name", "model", "description", "contactMaterial",
                "immersionProperties", "boundingObject", "physics", "locked", "radarCrossSection",
                "recognitionColors", "linearVelocity", "angularVelocity", "translationStep", "rotationStep"}
# fields only robots have: an unknown node (a PROTO not found) that sets one was a robot
ROBOT_ONLY_FIELDS = {"controller", "controllerArgs", "supervisor", "synchronization", "customData", "window",
                     "remoteControl", "battery", "selfCollision"}
SOLIDS = {"Robot", "Solid"} | SENSORS | JOINTS     # Solid nodes (a joint: its end point) Webots never scales


@dataclass
class Owner:
    """What shapes, lights and devices found now belong to: the world, a solid or a robot."""

    kind: str                      # "world", "solid", "robot"
    data: dict
    parts: list[dict] = field(default_factory=list)
    keys: dict[tuple, dict] = field(default_factory=dict)      # visual parts by (geometry, frame)
    wheels: list[dict] = field(default_factory=list)           # motorised hinges (robots)
    free: list[dict] = field(default_factory=list)             # a robot's wheel axes with encoders, no motor
    tracks: list[dict] = field(default_factory=list)           # a robot's motorised Tracks (wbt/drive.py track_drive)
    placed: Frame = field(default_factory=Frame.identity)      # the owner's frame in the world


MAX_INNER_DEFS = 1024
"""DEF names of PROTO bodies kept per robot or top-level solid (getFromProtoDef); a body declares tens."""

MAX_DEF = 4096
"""The longest DEF name getFromProtoDef is asked for (a longer one is never found)."""

SCOPE_NODES = 20_000
"""Nodes read per PROTO instance for its body's DEF names (the rest of a huge body is not searched)."""


@dataclass(eq=False)
class _Scope:
    """A PROTO instance being walked: the bodies it is made of (``keys``), and, when a Supervisor is served
    it (``scope`` set: see ``Converter.open_scope``), its body's DEF names (``first``: name -> (id of the
    DEF'd node, its type)), those a served node took (``tagged``) and the entry that keeps the others."""

    node: Node
    keys: frozenset[str]
    scope: int | None = None
    owner: dict | None = None
    first: dict[str, tuple[int, str]] = field(default_factory=dict)
    tagged: set[str] = field(default_factory=set)


def _chain_keys(node: Node) -> frozenset[str]:
    from sensorium.server.world.proto.instantiate import chain_keys

    return chain_keys(node)


def _sub_nodes(node: Node) -> list[Node]:
    out: list[Node] = []
    for value in node.fields.values():
        if isinstance(value, Node):
            out.append(value)
        elif isinstance(value, list) and value and not isinstance(value[0], float | int | str | bool):
            out += [x for x in value if isinstance(x, Node)]
    return out


def _scope_defs(root: Node) -> dict[str, tuple[int, str]]:
    """The DEF names a PROTO instance's getFromProtoDef finds, as Webots' WbSupervisorUtilities searches:
    the nodes of its fields first, then depth first below each; a nested PROTO instance's own body is
    out of scope (its DEFs are its own), the nodes written here that it holds (its fields' values) are
    in. The first node of each name, with its type, at most :data:`SCOPE_NODES` nodes read."""
    from sensorium.server.world.proto.instantiate import body_of

    found: dict[str, tuple[int, str]] = {}

    def take(node: Node) -> None:            # its DEF, unless an earlier node holds the name
        if node.def_name and node.def_name not in found and len(node.def_name) <= MAX_DEF:
            found[node.def_name] = (id(node), node.type)

    level = _sub_nodes(root)
    for child in level:
        take(child)
    budget = SCOPE_NODES
    seen: set[int] = set()
    for child in level:
        stack: list[tuple[Node, frozenset[str]]] = [(child, frozenset())]
        while stack and budget > 0:
            node, hidden = stack.pop()
            if id(node) in seen:
                continue
            seen.add(id(node))
            budget -= 1
            if body_of(node) not in hidden:
                take(node)
            if node.proto is not None and node.instance_at is not None:
                hidden = hidden | _chain_keys(node)     # a nested instance: its body is its own scope
            stack += [(x, hidden) for x in reversed(_sub_nodes(node))]
    return found


# nodes that take a name but are no Solid: a SolidReference cannot name them
_NAMED_NOT_SOLID = frozenset({"RotationalMotor", "LinearMotor", "PositionSensor", "Brake", "Skin"})


def _solid_names(root: Node) -> set[str] | None:
    """The names of the Solids under the top-level node ``root`` (``root`` too): those a SolidReference
    inside it may name (Webots: a Solid with a common upper Solid). A Solid written without a name is
    "solid". None when the subtree is over :data:`SCOPE_NODES` nodes (not searched: nothing is refused)."""
    names: set[str] = set()
    stack, seen = [root], set()
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if len(seen) > SCOPE_NODES:
            return None
        name = node.fields.get("name")
        if isinstance(name, list) and len(name) == 1:
            name = name[0]
        if isinstance(name, str) and node.type not in _NAMED_NOT_SOLID:
            names.add(name)
        elif name is None and node.type == "Solid":
            names.add("solid")
        stack += _sub_nodes(node)
    return names


_PHYSICS_ONLY = frozenset({"Physics", "Damping", "ContactProperties", "ImmersionProperties", "Fluid", "Muscle"})


def _relative(url: str) -> bool:
    """Whether ``url`` is a relative path (no scheme, no root, no drive)."""
    u = url.strip().replace("\\", "/")
    return bool(u) and "://" not in u and not u.startswith("/") and not (len(u) > 1 and u[1] == ":") and "\0" not in u


def _world_relative(url: str, world: str) -> bool:
    """Whether ``url`` is a relative path naming a file in the world file's folder (and staying in it)."""
    u = url.strip().replace("\\", "/")
    if not _relative(u):
        return False
    folder = Path(world).resolve().parent
    path = (folder / u).resolve()
    return path.is_relative_to(folder) and path.is_file()


def _unserved_why(kind: str) -> str:
    """Why a DEF'd node of a PROTO's body is no Supervisor node here (getFromProtoDef's line)."""
    if kind in _PHYSICS_ONLY:
        return f"a {kind} node: physics only, which Sensorium does not simulate (no Supervisor node here)"
    if kind in LIGHTS:
        return f"a {kind} where Sensorium serves no Supervisor node for it"
    if kind in GEOMETRIES:
        return (f"a {kind} geometry of no visible Shape (a boundingObject's: Sensorium serves the geometries of "
                "visible shapes only)")
    if kind in ("JointParameters", "HingeJointParameters"):
        return f"a {kind} node: read through its joint's 'jointParameters' field here"
    return (f"a {kind} node, which Sensorium does not serve as a Supervisor node there (it serves the solids, "
            "devices, joints, Poses and Groups of robots, the solids, Poses and Groups inside top-level solids and "
            "visible shapes)")


class Converter:
    def __init__(self, wbt: WbtFile, source: str, search: Any = None, max_grid_points: int = MAX_GRID_POINTS):
        self.wbt = wbt
        self.max_grid_points = max_grid_points
        self.grid_points = 0               # ElevationGrid points converted so far (each use of a DEF counts)
        self.ear_budget = [EAR_CLIP_WORLD]  # corners² left for cutting concave IndexedFaceSet polygons into ears
        self.left_fanned: dict[str, int] = {}  # where an IndexedFaceSet kept concave polygons fanned: how many
        self.ear_cut: dict[int, tuple] = {}    # per IndexedFaceSet node cut into ears: (coordIndex, points, corners, fanned)
        self.clockwise: set[int] = set()       # the geometries of IndexedFaceSets written ccw FALSE (front: clockwise)
        self.source = source
        self.search = search               # proto.ProtoSearch: where asset urls resolve (resolve_url)
        self.world: dict[str, Any] = {"world_info": {}, "solids": [], "lights": [], "robots": []}
        self.warnings: list[str] = []
        self.skipped: Counter[str] = Counter()
        self.count = 0
        self.visits = 0
        self.solid_names: Counter[str] = Counter()
        self.robot_names: Counter[str] = Counter()
        self.checked: set[int] = set()     # nodes whose field names were checked
        self.device_depth = 0              # > 0 while inside a device's children (its joints are no wheels)
        self.riding: list[dict] = []       # the motor entries of the robot's joints being visited, innermost last
        self.robot_frames: dict[str, Frame] = {}     # each robot's frame in the world, by its name
        self.riders: dict[str, list[dict]] = {}      # the robots riding a robot being visited, by its name
        self.in_rider: str | None = None             # visiting a robot that rides another: that carrier's name
        self.coupled_nodes: dict[int, Node] = {}   # id(motor entry) -> its node, for a 'group::part' name
        self.device_where: dict[int, str] = {}   # id(device entry) -> where its node is written
        self.led_of: dict[int, tuple[dict, Frame]] = {}   # id(light node) -> (its LED's entry, the LED's frame)
        self.checked_scale: set[int] = set()   # Transforms whose scale was sanitised (warned once)
        self.checked_grids: set[int] = set()   # ElevationGrids sanitised (warned once: a shape and its boundingObject)
        self.constrained: set[int] = set()     # Transforms in boundingObjects whose scale Webots constrains
        self.defs: set[str] = set()        # DEF names kept (def_name)
        self.textured: dict[int, tuple[int, int, str, str]] = {}   # textures not loaded → (line, column, why)
        self.robot_fields = set(wm.Robot.model_fields)
        self.device_kinds = {k for k in SENSORS if hasattr(wm, k)}
        self.instances: list[tuple[str, tuple[str, int, int]]] = []   # PROTO instances being walked (name, at)
        self.asset_files: set[Path] = set()   # asset files outside the world's folder this world may read
        self.cad_meshes: set[int] = set()     # the Mesh nodes a CadShape's materials became (cad_shape)
        self.cad_read: dict[tuple[Path, str], Any] = {}   # a CadShape file's materials, read once (DEF/USE)
        self.losses: list[Loss] = []      # robots, sensor devices and sensor-visible shapes lost (report.py)
        self.resets_said: set[str] = set()   # Webots' field resets told (a node USEd twice: once)
        # the nodes inside the robot being converted, as a Supervisor walks them (schemas.world.NestedNode):
        # None outside a robot; the stack holds (node, its entry's index) of the nodes being walked
        self.tree: list[dict] | None = None
        self.tree_stack: list[tuple[Node, int]] = []
        self.tree_field = "children"       # the field the next node walked sits in (a joint's endPoint, ...)
        self.builtin_proto: str | None = None   # a built-in PROTO being expanded (the expansion's node names it)
        self.nested_defs: set[int] = set()      # nested nodes whose DEF is kept (a USE of one is a copy without it)
        self.shared_nodes: dict[int, int] = {}  # id(appearance or material node) -> its number (its USEs share it)
        # getFromProtoDef: the PROTO instances being walked (innermost last), the robot or top-level solid whose
        # entries are being made, and the number the next PROTO instance nested in a top-level solid gets
        self.scopes: list[_Scope] = []
        self.top_walked: Node | None = None          # the top-level node being walked
        self.top_solid_names: set[str] | None = None   # its Solids' names, once a SolidReference asks (_solid_names)
        self.top_names_read = False
        self.inner_owner: dict | None = None
        self.scope_serial = 0
        # the Poses, Transforms and Groups inside solids (schemas.world.SolidPose): the one being walked in each
        # solid (id of its data -> its index in the solid's `poses`), and a counter giving what a solid holds its
        # file order among its parent's children (`seq`)
        self.pose_at: dict[int, int] = {}
        self.node_seq = 0
        self.lights_seen = 0               # lights on, or an LED's, anywhere (the world's, solids', robots')
        self.image_lit = False             # a TexturedBackground or a Background with cube maps (Webots' IBL)

    # ------------------------------------------------------------ messages
    def where(self, node: Node, pos: tuple[int, int] | None = None) -> str:
        """``file:line:col`` of a node (or of ``pos`` in its file); a node read from a PROTO file also
        names the PROTO instance written in the world that brought it."""
        line, col = pos or (node.line, node.col)
        src = node.source or self.source
        out = f"{src}:{line}:{col}"
        if src != self.source and self.instances:
            name, (file, i_line, i_col) = self.world_instance()
            out += f" (in PROTO {name} at {file}:{i_line}:{i_col})"
        return out

    def world_instance(self) -> tuple[str, tuple[str, int, int]]:
        """The outermost PROTO instance being walked that the world file itself writes."""
        for name, at in self.instances:
            if at[0] == self.source:
                return name, at
        return self.instances[0]

    def at(self, node: Node) -> tuple[int, int, str]:
        """(line, column, what) in the world file for converted-path bookkeeping: a node of a PROTO file
        is placed at the instance the world writes."""
        src = node.source or self.source
        if src == self.source or not self.instances:
            return node.line, node.col, node.type
        name, (_, line, col) = self.world_instance()
        return line, col, f"{node.type} of PROTO {name}"

    def warn(self, node: Node, message: str) -> None:
        self.warnings.append(f"{self.where(node)}: {message}")

    def warn_once(self, node: Node, message: str) -> None:
        """A warning about a node itself, said once however often the node is used (a DEF shape
        USEd as its Solid's boundingObject too)."""
        line = f"{self.where(node)}: {message}"
        if line not in self.resets_said:
            self.resets_said.add(line)
            self.warnings.append(line)

    def field_reset(self, node: Node, name: str, message: str) -> None:
        """A field value Webots would not use, reset as Webots does (wbt/resets.py): one warning at
        the field's line, said once however often the node is used."""
        line = f"{self.where(node, node.field_pos.get(name))}: {message}"
        if line not in self.resets_said:
            self.resets_said.add(line)
            self.warnings.append(line)

    def drop(self, node: Node, message: str, kind: str, name: str = "", robot: str = "") -> None:
        """A loss that changes what sensors read (``kind``: a robot, a sensor device, a solid or
        shape sensors see, an unknown node): a warning that ``validate`` counts as an error unless
        ``--allow-skipped``, and what a controller asking for a dropped robot is told."""
        loss = Loss(kind, name, self.where(node), message, robot)
        self.warnings.append(loss.text)
        self.losses.append(loss)

    def lose_shape(self, node: Node, message: str, owner: Owner) -> None:
        """A shape sensors would see, left out (a mesh file missing, a geometry not read here)."""
        self.drop(node, message, "shape", owner.data.get("name", "") if owner.kind != "world" else "")

    def fields(self, node: Node) -> Fields:
        return Fields(node, node.source or self.source, self.field_reset)

    def error(self, node: Node, message: str) -> WbtSyntaxError:
        return WbtSyntaxError(node.source or self.source, node.line, node.col, message)

    def walk(self, node: Node) -> None:
        """Count a node walked (DEF/USE can make a small file a huge tree)."""
        self.visits += 1
        if self.visits > MAX_VISITS:
            raise self.error(node, f"more than {MAX_VISITS} nodes to walk after DEF/USE expansion")

    def tick(self, node: Node) -> None:
        self.count += 1
        if self.count > MAX_PARTS:
            raise self.error(node, f"more than {MAX_PARTS} shapes, devices and lights after DEF/USE expansion")

    # ------------------------------------------------------------ top level
    def run(self) -> dict:
        world = Owner("world", {})
        self.world["world_info"] = {"name": Path(self.source).stem}
        top_nodes = []     # the root's children in file order (schemas.world.TopNode)
        for node in self.wbt.nodes:
            before = [len(self.world[k]) for k in ("robots", "solids", "lights")]
            self.visit(node, Frame.identity(), world, top=True)
            became = {k: len(self.world[k]) - n for k, n in zip(("robots", "solids", "lights"), before)}
            top_nodes.append(self.top_node(node, became))
        self.world["top_nodes"] = top_nodes
        if world.parts:   # shapes outside any Solid: one solid holding them (visual only, as in Webots)
            self.world["solids"].append(self.solid_dict(world, {"name": self.unique_name("shapes")}))
        if self.textured:
            self.warnings.append(self.textures_not_loaded())
        if self.left_fanned:
            where, n = next(iter(self.left_fanned.items())), len(self.left_fanned)
            self.warnings.append(
                f"{where[0]}: IndexedFaceSet: {sum(self.left_fanned.values())} concave polygon(s) left fanned from their "
                f"first corner (over {EAR_CLIP_CORNERS} corners, or past the world's {EAR_CLIP_WORLD:,} corners² for "
                "cutting them into ears): they may cover space outside their outline"
                + (f" ({n} IndexedFaceSets, the first here)" if n > 1 else ""))
        self.unlit_cameras_note()
        if self.skipped:
            listed = ", ".join(f"{k} x{v}" if v > 1 else k for k, v in sorted(self.skipped.items()))
            self.warnings.append(f"{self.source}: skipped nodes that do not matter to these sensors: {listed}")
        return {k: v for k, v in self.world.items() if v}

    def top_node(self, node: Node, became: dict[str, int]) -> dict:
        """A top-level node as the Supervisor lists it (schemas.world.TopNode): its base type, the
        PROTO it is an instance of (an expanded one, or one Sensorium builds in), its DEF, what it
        became, and a Viewpoint's or Background's values the Supervisor reads."""
        base = KNOWN_PROTO_BASES.get(node.type, node.type)
        entry: dict[str, Any] = {"type": base}
        proto = node.proto or (node.type if node.type in KNOWN_PROTO_BASES else None)
        if proto:
            entry["proto"] = proto
        self.interface(node, entry)
        if node.def_name:
            entry["def_name"] = node.def_name
        if base in SCENERY_VALUES:
            entry["fields"] = self.scenery_values(node, base)
        return entry | {k: n for k, n in became.items() if n}

    def scenery_values(self, node: Node, base: str) -> dict[str, Any]:
        """The written values of a Viewpoint's or Background's fields the Supervisor serves (the
        others answer Webots' defaults there); a value that does not read is left out with a warning
        (these nodes change no sensor reading, so the world still loads)."""
        f = self.fields(node)
        out: dict[str, Any] = {}
        for name, kind in SCENERY_VALUES[base].items():
            if not f.has(name):
                continue
            try:
                if kind == "SFFloat":
                    out[name] = f.num(name, 0.0)
                elif kind == "SFString":
                    out[name] = f.string(name, "")
                elif kind == "MFColor":
                    out[name] = [list(c) for c in f.colors(name, [])]
                else:
                    out[name] = list(f.vec(name, (0.0,) * (4 if kind == "SFRotation" else 3)))
            except WbtSyntaxError as e:
                self.warn(node, f"{e.message}; the Supervisor reads Webots' default for it")
        return out

    def unique_name(self, name: str) -> str:
        self.solid_names[name] += 1
        n = self.solid_names[name]
        return name if n == 1 else f"{name}({n - 1})"

    def unique_robot(self, name: str) -> str:
        """Robot names address topics and services, so they must differ (Webots only warns)."""
        self.robot_names[name] += 1
        n = self.robot_names[name]
        return name if n == 1 else f"{name}({n - 1})"

    def world_info(self, node: Node) -> None:
        f = self.fields(node)
        step = f.num("basicTimeStep", 32.0)
        if step != int(step) or step < 1:
            raise f.error("basicTimeStep", f"must be a whole number of milliseconds >= 1 here, got {step}")
        seed = f.integer("randomSeed", 0)
        if seed < 0:
            raise f.error("randomSeed", "a negative (time-based) seed is not supported: runs here are reproducible")
        system = f.string("coordinateSystem", "ENU")
        if system not in ("ENU", "NUE"):
            raise f.error("coordinateSystem", f"{system!r} is not supported (ENU or NUE)")
        info = {"name": f.string("title", "") or Path(self.source).stem, "basic_time_step": int(step),
                "random_seed": seed, "coordinate_system": system}
        evaporation = f.num("inkEvaporation", 0.0)
        if evaporation > 0.0:          # Webots' pen ink fading (a value <= 0 never evaporates)
            info["ink_evaporation"] = evaporation
        gravity = f.num("gravity", 9.81)        # what an accelerometer at rest reads (a Mars world: 3.71)
        if gravity < 0.0:
            raise f.error("gravity", f"{gravity:g} < 0 (gravity pointing up) is not supported here")
        if gravity != 9.81:
            info["gravity"] = gravity
        gps = f.string("gpsCoordinateSystem", "local")     # what GPS devices read (Webots: WGS84, else local)
        if gps not in ("local", "WGS84"):
            self.warn(node, f"WorldInfo.gpsCoordinateSystem {gps!r} is neither \"WGS84\" nor \"local\": local "
                            "coordinates, as Webots returns for any value but \"WGS84\"")
            gps = "local"
        if gps != "local":
            info["gps_coordinate_system"] = gps
        reference = f.vec("gpsReference", (0.0, 0.0, 0.0))
        if tuple(reference) != (0.0, 0.0, 0.0):
            info["gps_reference"] = list(reference)
        self.world["world_info"] = info

    def fog(self, node: Node, f: Fields) -> None:
        """Webots' Fog, the first one only (Webots warns about the others), with Webots' resets: a
        negative visibilityRange is 0 (no fog), colour components outside [0, 1] are clamped, an
        unknown fogType is LINEAR (each with a warning); fogType is read case-blind, as Webots."""
        if "fog" in self.world:
            self.warn(node, "only the first Fog node is taken into account (Webots); this one is skipped")
            return
        color = f.vec("color", (1.0, 1.0, 1.0))
        if min(color) < 0.0 or max(color) > 1.0:
            self.warn(node, f"Fog color {' '.join(f'{c:g}' for c in color)} clamped to [0, 1] (Webots resets it)")
            color = tuple(min(max(c, 0.0), 1.0) for c in color)
        visibility = f.num("visibilityRange", 0.0)
        if visibility < 0.0:
            self.warn(node, f"Fog visibilityRange {visibility:g} < 0 reset to 0: no fog (Webots)")
            visibility = 0.0
        fog_type = f.string("fogType", "LINEAR")
        if fog_type.upper() not in ("LINEAR", "EXPONENTIAL", "EXPONENTIAL2"):
            self.warn(node, f"unknown Fog fogType {fog_type!r}: LINEAR, as Webots")
            fog_type = "LINEAR"
        self.world["fog"] = {"color": list(color), "visibility_range": visibility, "fog_type": fog_type.upper()}

    # ------------------------------------------------------------ the walk
    def visit(self, node: Node, frame: Frame, owner: Owner, top: bool = False) -> None:
        if top:
            self.top_walked, self.top_names_read = node, False
        pushed = self.tree_node(node, frame, owner)
        try:
            if node.proto is not None and node.instance_at is not None:
                self.instances.append((node.proto, node.instance_at))
                scope = _Scope(node, _chain_keys(node))
                self.scopes.append(scope)
                if pushed and self.tree is not None:       # a PROTO instance inside a robot: its entry's index
                    self.open_scope(node, len(self.tree) - 1 if self.tree_stack[-1][0] is node else None)
                try:
                    self.visit_node(node, frame, owner, top)
                finally:
                    self.instances.pop()
                    self.scopes.pop()
                    self.close_scope(scope)
            else:
                self.visit_node(node, frame, owner, top)
        finally:
            if pushed:
                self.tree_stack.pop()

    # ------------------------------------------------------------ getFromProtoDef: the DEFs of a PROTO's body
    def open_scope(self, node: Node, scope: int | None) -> None:
        """Make the innermost PROTO instance being walked, ``node``, a Supervisor node whose body's DEFs
        are found (``scope``: -1 the robot or top-level solid being made, else its entry's index in the
        robot's ``nodes`` or its number in the top-level solid); its DEFs are read now (:func:`_scope_defs`)."""
        top = self.scopes[-1] if self.scopes else None
        if top is None or top.node is not node or top.scope is not None or scope is None or self.inner_owner is None:
            return
        top.scope, top.owner = scope, self.inner_owner
        top.first = _scope_defs(node)

    def inner_defs(self, node: Node | None, role: str = "") -> list[dict]:
        """The DEFs ``node`` (a node a Supervisor is served) answers getFromProtoDef for: the DEF'd node of
        each enclosing PROTO instance's scope (its first place: a USE of it is a copy without the DEF)."""
        out: list[dict] = []
        name = None if node is None else node.def_name
        if not name:
            return out
        for scope in self.scopes:
            if scope.scope is None or scope.node is node or scope.owner is not self.inner_owner:
                continue
            hit = scope.first.get(name)
            if hit is None or hit[0] != id(node) or name in scope.tagged:
                continue
            scope.tagged.add(name)
            out.append({"scope": scope.scope, "name": name} | ({"role": role} if role else {}))
        return out

    @staticmethod
    def close_scope(scope: _Scope) -> None:
        """The DEFs of the scope no served node took: each with why it is no node here (getFromProtoDef's line)."""
        if scope.owner is None:
            return
        notes = scope.owner.setdefault("inner_defs", [])
        for name, (_, kind) in scope.first.items():
            if name not in scope.tagged and len(notes) < MAX_INNER_DEFS:
                notes.append({"scope": scope.scope, "name": name, "why": _unserved_why(kind[:64])})
        if not notes:
            del scope.owner["inner_defs"]

    # ------------------------------------------------------------ the nodes a Supervisor walks in a robot
    def tree_node(self, node: Node, frame: Frame, owner: Owner) -> bool:
        """Record a node inside the robot being converted (schemas.world.NestedNode) and make it the
        parent of what is walked inside it; True when recorded (the caller pops it)."""
        field, self.tree_field = self.tree_field, "children"
        proto, self.builtin_proto = self.builtin_proto, None
        t = node.type
        if self.tree is None or owner.kind != "robot":
            return False
        posed = t in ("Pose", "Transform", "Solid") or t in SENSORS or t in OTHER_DEVICES
        if not (posed or t in ("Group", "Slot") or t in JOINTS) or (posed and not frame.rigid) or t == "Charger":
            return False
        entry: dict[str, Any] = {"type": t}
        if posed:
            entry["pose"] = self.child_frame(node, frame).pose()
        if t == "Transform":
            self.written_scale(node, entry)
        if posed and t not in ("Pose", "Transform"):    # a Solid's or device's Physics (getCenterOfMass)
            entry.update(solid_mass(self, node))
        if t in ("HingeJoint", "SliderJoint"):
            parameters = self.fields(node).node_("jointParameters")
            if parameters is not None:
                entry["joint_parameters"] = True
                if self.nested_def(parameters):
                    entry["joint_parameters_def"] = parameters.def_name
            self.joint_frame(node, frame, entry)      # for getUrdf, whatever turns the joint (or nothing)
        self.tree_entry(node, entry, field, proto)
        self.tree_stack.append((node, len(self.tree) - 1))
        return True

    @staticmethod
    def interface(node: Node, entry: dict) -> None:
        """A PROTO instance's interface fields, for the Supervisor (proto.interface_levels)."""
        if node.proto is not None and "interface" in node.__dict__:
            from sensorium.server.world.proto import interface_levels

            entry["interface"] = interface_levels(node)

    def tree_entry(self, node: Node, entry: dict, field: str, builtin: str | None = None) -> None:
        """Add ``entry`` (type, pose) for ``node`` under the node being walked: its PROTO, its DEF
        (one the world file writes: a PROTO's internal nodes are not found by DEF, as in Webots) and
        its name."""
        assert self.tree is not None
        proto = node.proto or builtin
        if proto:
            entry["proto"] = proto
        self.interface(node, entry)
        if self.nested_def(node):
            entry["def_name"] = node.def_name
        if node.type == "Solid" or node.type in SENSORS or node.type in OTHER_DEVICES or node.type in MOTORS:
            default = "solid" if node.type == "Solid" else fx.DEVICE_NAMES.get(
                node.type, OTHER_NAMES.get(node.type, OTHER_MOTOR_NAMES.get(node.type, node.type.lower())))
            entry["name"] = self.fields(node).string("name", default)
        if self.tree_stack:
            entry["parent"] = self.tree_stack[-1][1]
        if field != "children":
            entry["field"] = field
        tags = self.inner_defs(node)
        if tags:
            entry["inner_defs"] = tags[:64]
        self.written_at(node, entry)
        self.tree.append(entry)

    def nested_def(self, node: Node) -> bool:
        """Whether a nested node keeps its DEF: the world file writes it, and this is the DEF's node,
        not a USE of it (the parser hands the same node for both; Webots' USE copies have no DEF)."""
        if not node.def_name or not self.written(node) or id(node) in self.nested_defs:
            return False
        self.nested_defs.add(id(node))
        return True

    def written_at(self, node: Node, entry: dict) -> None:
        """``entry``'s ``written_at``: where the world file writes ``node`` (a PROTO instance: the instance),
        for a Supervisor's exportString; for a node a PROTO's body made, ``made_at``: where that body writes it."""
        if node.instance_at is not None and node.instance_at[0] == self.source:
            entry["written_at"] = [node.instance_at[1], node.instance_at[2]]
        elif node.instance_at is None and (node.source or self.source) == self.source:
            entry["written_at"] = [node.line, node.col]
        elif node.instance_at is not None:
            entry["made_at"] = [node.instance_at[1], node.instance_at[2]]
        elif node.line >= 1 and node.col >= 1:
            entry["made_at"] = [node.line, node.col]

    def written(self, node: Node) -> bool:
        """Whether the world file writes ``node`` (or the PROTO instance it is): a node of a PROTO's
        body is the PROTO's internal node, which Webots' getFromDef does not find."""
        return (node.source or self.source) == self.source or (
            node.instance_at is not None and node.instance_at[0] == self.source)

    def tree_device(self, node: Node, device: dict) -> None:
        """The device entry of the node being walked (getFromDevice; its final name is resolved at the robot's end)."""
        if self.tree is not None and self.tree_stack and self.tree_stack[-1][0] is node:
            self.tree[self.tree_stack[-1][1]]["_device"] = device

    def tree_done(self, robot: dict, tree: list[dict]) -> None:
        """The robot's nodes with their devices' final names (after unique_devices)."""
        for entry in tree:
            device = entry.pop("_device", None)
            if device is not None and any(d is device for d in robot["devices"]):
                entry["device"] = device["name"]
                entry.setdefault("name", device["name"])
        if tree:
            robot["nodes"] = tree

    def visit_node(self, node: Node, frame: Frame, owner: Owner, top: bool = False) -> None:
        self.walk(node)
        t = node.type
        f = self.fields(node)
        self.typos(node)
        if t == "WorldInfo":
            if not top:
                raise self.error(node, "WorldInfo must be a top-level node")
            if "basic_time_step" in self.world["world_info"]:    # Webots reads the first one
                self.warn(node, "duplicate WorldInfo node: only the first one counts (as in Webots); this one is "
                                "skipped")
            else:
                self.world_info(node)
        elif t == "Background" and top and f.has("skyColor"):     # what cameras see past everything
            self.note_image_lighting(node)
            sky = f.colors("skyColor", [(0.0, 0.0, 0.0)])
            self.world["background"] = {"sky_color": list(sky[0]) if sky else [0.0, 0.0, 0.0]}
            self.skipped["Background (all but its skyColor)"] += 1     # its textures, luminosity are not read
        elif t == "Fog":                 # cameras blend it in
            if top:
                self.fog(node, f)
            else:
                self.warn(node, "a Fog node counts only at the top level of a world (Webots allows it nowhere "
                                "else); skipped")
        elif t == "Viewpoint":           # its values are kept (top_node): the Supervisor's and snapshots' view
            pass
        elif t == "Billboard":
            self.billboard(node)
        elif t in SKIPPED:
            self.note_image_lighting(node)
            if t != "TexturedBackground":     # a PROTO not read: the PROTO note says what cameras lose
                self.skipped[t] += 1
        elif not frame.rigid and (t in SOLIDS or t in OTHER_DEVICES):
            self.scaled_solid(node, owner)
        elif t == "Fluid":               # a Solid of water or air that immersed solids float in (physics only)
            self.warn(node, f"Fluid {f.string('name', 'fluid')!r}: buoyancy, drag and its stream are not simulated "
                            "(no physics); its shapes are kept as a solid that cameras, lidars and infra-red sensors "
                            "see, its boundingObject (the fluid's volume) is no obstacle")
            self.solid(node, frame, owner, "fluid", bounding=False)
        elif t == "Charger":             # a Solid that recharges robots' batteries (README 'Battery and Charger')
            entry = self.solid(node, frame, owner, "solid")
            glow = entry.pop("_glow_shapes", 0) if entry is not None else 0
            glow_lights = entry.pop("_glow_lights", 0) if entry is not None else 0
            glow_solids = entry.pop("_glow_solids", 0) if entry is not None else 0
            if owner.kind != "world" or entry is None:
                self.warn(node, f"Charger {f.string('name', 'solid')!r}: only a top-level Charger recharges "
                                "robots here; its shapes and lights are kept")
            else:
                charger: dict[str, Any] = {"solid": entry["name"], "radius": f.non_negative("radius", 0.04, 0.04),
                                           "emissive_color": list(f.color("emissiveColor", (0.0, 1.0, 0.0))),
                                           "gradual": f.flag("gradual", True),
                                           "glow_shapes": glow}
                if glow_lights:         # (the model's defaults otherwise: a Charger without them dumps as before)
                    charger["glow_lights"] = glow_lights
                if glow_solids:
                    charger["glow_solids"] = glow_solids
                battery = self.battery_values(node, f"Charger {entry['name']!r}")
                if battery:
                    charger["battery"] = battery
                self.world.setdefault("chargers", []).append(charger)
        elif t in OTHER_DEVICES:
            if owner.kind == "robot":
                inner = self.child_frame(node, frame)
                data = None
                if t in wm.DEVICE_TYPES:     # listed (simulated kinds take their schema defaults)
                    self.tick(node)
                    data = self.unsimulated(node, inner, owner)
                    if t == "Pen":             # a Pen keeps its fields (simulated: it inks)
                        data.update(fx.pen(f))
                    elif t == "Display":       # its size (below 1: 1, as Webots sets it)
                        data.update(fx.display(f))
                    elif t == "VacuumGripper":     # its strengths and contact points, Webots' resets
                        data.update(fx.vacuum_gripper(f))
                    elif t == "Connector":     # its tolerances with WbConnector's resets
                        data.update(fx.connector(f))
                    if t in wm.UNSIMULATED_DEVICE_TYPES:
                        self.warn(node, f"{t} {data['name']!r} of robot {owner.data['name']!r}: listed (a controller "
                                        "finds it), not simulated here: its functions answer Webots' \"no value\"")
                elif t == "Track":           # a Solid whose device field holds its motor (and sensor, brake)
                    if "scale" in node.fields:     # a Solid's scale before R2023a (Webots' track sample halves its Tracks)
                        inner = self.child_frame(node, frame, self.transform_scale(node))
                    if f.node_("animatedGeometry") is not None:     # the belt Webots draws along its wheels
                        self.skipped["Track.animatedGeometry"] += 1
                    motors, sensors = self.joint_devices(node, owner)
                    if motors or sensors or f.nodes("device"):
                        what = ("its motor's position moves kinematically (its sensor reads it)" if motors and sensors
                                else "its motor's position moves kinematically" if motors     # Webots' ConveyorBelt
                                else "its sensor reads a still position (no motor)" if sensors
                                else "its devices do nothing")
                        line = f"Track {f.string('name', 'solid')!r}: {what}; the belt and its wheels do not move here"
                        if motors:      # two of them may drive the robot (said in drive() if they do not)
                            self.track(node, inner, owner, motors[0], line)
                        else:
                            self.warn(node, line)
                start = len(owner.parts)
                self.device_contents(node, inner, owner, data)
                if t == "Display" and data is not None:
                    self.display_screen(node, owner, start, data)
            elif t == "Connector":       # a solid that robots' connectors dock with (Webots allows it)
                out = self.solid(node, frame, owner, "connector")
                if out is not None:
                    entry = {"name": out["name"], "device": "Connector", **self.device_fields(node),
                             **fx.connector(f)}
                    if f.string("model", ""):
                        entry["model"] = f.string("model", "")
                    out.setdefault("connectors", []).append(entry)
            else:     # a device outside a robot is still a Solid whose shapes rays see
                self.warn(node, f"{t} outside a Robot: not a device here (devices belong to robots); its shapes "
                                "are kept as a solid")
                self.solid(node, frame, owner, OTHER_NAMES.get(t, t.lower()))
        elif t == "Group":
            mark = self.solid_pose(node, frame, owner)
            try:
                for child in f.nodes("children"):
                    self.visit(child, frame, owner)
            finally:
                self.end_solid_pose(owner, mark)
        elif t == "Propeller":           # a robot's motor (listed: controllers ask for it) and its helix
            if owner.kind == "robot":
                self.joint_devices(node, owner)
                if f.node_("device") is not None:
                    self.warn(node, "Propeller: its motor's position moves kinematically; its thrust and torque "
                                    "are not simulated")
            helix = f.node_("slowHelix")     # what Webots shows below fastHelixThreshold (at rest)
            if helix is not None:
                self.visit(helix, frame, owner)
        elif t == "Slot":                # Webots' base node: its endPoint sits in the Slot's parent frame
            end = f.node_("endPoint")
            if end is not None:
                self.tree_field = "endPoint"
                self.visit(end, frame, owner)
        elif t in ("Pose", "Transform") and top and node.def_name and self.marker(node, frame):
            # a top-level DEF Pose holding only shapes (a target a Supervisor moves, as Webots' curriculum
            # ball): a solid of its own without boundingObject, so its translation and rotation are served
            self.solid(node, frame, owner, node.def_name, bounding=False)
        elif t in ("Pose", "Transform"):
            inner = self.child_frame(node, frame)
            mark = self.solid_pose(node, inner, owner, frame)
            try:
                for child in f.nodes("children"):
                    self.visit(child, inner, owner)
            finally:
                self.end_solid_pose(owner, mark)
        elif t == "TrackWheel":          # a Pose at (position.x, 0, position.y) in its Track's frame (Webots)
            px, py = f.vec("position", (0.0, 0.0))
            inner = frame.then((px, 0.0, py), (0.0, 0.0, 1.0, 0.0), (1.0, 1.0, 1.0))
            for child in f.nodes("children"):
                self.visit(child, inner, owner)
        elif t == "Shape":
            self.shape(node, frame, owner, seen_by="visual")
        elif t == "CadShape":     # a visual mesh file with its own materials (COLLADA's read)
            self.cad_shape(node, frame, owner)
        elif t in LIGHTS:
            self.light(node, frame, owner)
        elif t == "Robot":
            name = self.fields(node).string("name", "robot")
            if owner.kind == "robot" and self.plain_robot(node):
                self.warn(node, f"Robot {name!r} inside robot {owner.data['name']!r}: no controller and no device: "
                                f"its shapes and bounding objects are kept as part of {owner.data['name']!r}'s body "
                                "(a robot riding on another robot is not simulated here)")
                self.solid(node, frame, owner)
            elif owner.kind == "robot" and (self.riding or self.in_rider):
                self.drop(node, f"Robot {name!r} inside robot {owner.data['name']!r}: a robot riding on another "
                                "robot's joint, or on a robot that rides itself, is not supported here; dropped with "
                                "everything inside it", "robot", name)
            elif owner.kind == "robot":      # it rides the robot, fixed in its frame (Webots: a static child)
                riding, carrier = self.riding, owner.data
                self.in_rider = carrier["name"]
                try:
                    self.robot(node, self.robot_frames[carrier["name"]].compose(frame))
                finally:
                    self.riding, self.in_rider = riding, None
                rider = self.world["robots"].pop()      # listed after its carrier, as Webots' scene tree has it
                rider["carried_by"] = {"robot": carrier["name"], "frame": self.child_frame(node, frame).pose()}
                if not np.array_equal(frame.translation, np.zeros(3)) or not np.array_equal(frame.rotation, np.eye(3)):
                    rider["carried_by"]["parent"] = frame.pose()     # Poses between: its fields are in theirs
                self.riders.setdefault(carrier["name"], []).append(rider)
            else:     # at the top or nested in solids and groups: a robot placed where they put it
                self.robot(node, owner.placed.compose(frame))
        elif t == "Solid":
            self.solid(node, frame, owner)
        elif t in SENSORS or t in MOTORS:
            self.device(node, frame, owner)
        elif t in JOINTS:
            self.joint(node, frame, owner)
        elif t in BUILTIN_PROTOS:
            self.stand_in_typos(node)
            system = self.world["world_info"].get("coordinate_system", "ENU")
            expanded = BUILTIN_PROTOS[t](node, f, system)
            expanded.def_name = node.def_name
            self.builtin_proto = t
            self.visit(expanded, frame, owner, top)
        elif t in GEOMETRIES:
            self.warn(node, f"{t} outside a Shape or boundingObject: ignored")
        else:
            from sensorium.server.world.proto.interface import BASE_NODES

            named = node.fields.get("name")
            robot_like = any(k in node.fields for k in ROBOT_ONLY_FIELDS)   # a robot PROTO instance, surely
            if t in BASE_NODES:      # a Webots node (Fluid, Billboard, ...), not a PROTO whose file is missing
                why = f"{t}: a Webots node not read here (or not in its place); skipped (with everything inside it)"
            else:
                why = (f"{t}: not a built-in node or PROTO here; skipped (with everything inside it). "
                       f"Built-in PROTOs: {', '.join(sorted(BUILTIN_PROTOS))}")
            self.drop(node, why, "robot" if robot_like else "node", named if isinstance(named, str) else t)

    # ------------------------------------------------------------ the Poses and Groups a Supervisor walks in a solid
    def solid_pose(self, node: Node, inner: Frame, owner: Owner, parent: Frame | None = None) -> int | None:
        """Record a Pose, Transform or Group inside a solid (``inner``: its frame there; a Group's is its
        parent's; ``parent``: a Pose's or Transform's parent frame, None: ``inner``) as the Supervisor node it is
        (schemas.world.SolidPose) and make it the parent of what is walked inside it; returns the parent to
        restore (None: not recorded: outside a solid, or under a scaled Transform, whose fields no longer map to
        its place rigidly; a scaled Transform itself is a node, its own frame rigid in its parent's)."""
        if owner.kind != "solid" or not (parent if parent is not None else inner).rigid:
            return None
        poses = owner.data.setdefault("poses", [])
        above = self.pose_at.get(id(owner.data), -1)
        entry: dict[str, Any] = {"type": node.type, "seq": self.next_seq()}
        if above >= 0:
            entry["parent"] = above
        if node.type != "Group":
            entry["pose"] = inner.pose()
        if node.type == "Transform":
            self.written_scale(node, entry)
        if self.nested_def(node):
            entry["def_name"] = node.def_name
        tags = self.inner_defs(node)
        if tags:
            entry["inner_defs"] = tags[:64]
        self.written_at(node, entry)
        poses.append(entry)
        self.pose_at[id(owner.data)] = len(poses) - 1
        return above

    def end_solid_pose(self, owner: Owner, mark: int | None) -> None:
        if mark is not None:
            self.pose_at[id(owner.data)] = mark

    def next_seq(self) -> int:
        self.node_seq += 1
        return self.node_seq

    def in_solid_pose(self, owner: Owner, entry: dict, key: str = "parent") -> None:
        """A node inside a solid (a nested solid, a Shape, a light): the Pose or Group of the solid holding
        it (``parent``, as ``key``) and its file order there (``seq``)."""
        if owner.kind != "solid":
            return
        above = self.pose_at.get(id(owner.data), -1)
        if above >= 0:
            entry[key] = above
        entry["seq"] = self.next_seq()

    @staticmethod
    def drop_seq(solid: dict) -> bool:
        """Leave out the file order of a top-level solid's nodes when no Pose or Group is among them (the
        solids', shapes' and lights' other fields order them then); True when one is."""
        stack, posed, held = [solid], False, []
        while stack:
            s = stack.pop()
            posed = posed or bool(s.get("poses"))
            held += [p["node"] for p in s.get("shapes", ()) if isinstance(p.get("node"), dict)]
            held += [lt["node"] for lt in s.get("lights", ()) if isinstance(lt.get("node"), dict)]
            held += s.get("children", [])
            stack += s.get("children", [])
        if not posed:
            for entry in held:
                entry.pop("seq", None)
        return posed

    def billboard(self, node: Node) -> None:
        """A Billboard: Webots pins its children to the 3D view's viewpoint, and no Camera sees them nor
        their shadows (Webots' reference), so no device reads anything of it: skipped as what does not
        matter to sensors. A node inside that would matter (a Solid, a device, a light, a node not read
        here) makes it a loss, naming that node."""
        stack: list[Any] = [node.fields.get("children")]
        while stack:
            value = stack.pop()
            if isinstance(value, list):
                stack.extend(value)
            elif isinstance(value, Node):
                if value.type not in BILLBOARD_CONTENT:
                    named = node.fields.get("name")
                    self.drop(node, f"Billboard holding {value.type} (line {value.line}): only Webots' 3D view shows a "
                                    "Billboard's children, and a Solid, device or light there is not simulated here; "
                                    "skipped with everything inside it", "node",
                              named if isinstance(named, str) else "Billboard")
                    return
                stack.extend(value.fields.values())
        self.skipped["Billboard"] += 1

    def plain_robot(self, node: Node) -> bool:
        """A Robot with no controller (``<none>`` or empty) holding only shapes and solids, through
        Poses, Transforms, Groups and Slots (Webots' JetsonNano board on the JetBot): nothing of it
        runs, so riding its outer robot as part of that body is all Webots does with it."""
        f = self.fields(node)
        if f.string("controller", "<generic>") not in ("<none>", ""):
            return False
        stack = list(f.nodes("children"))
        while stack:
            child = stack.pop()
            if child.type not in PLAIN_ROBOT_CONTENT:
                return False
            sub = self.fields(child)
            stack += sub.nodes("endPoint") if child.type == "Slot" else sub.nodes("children")
        return True

    def note_image_lighting(self, node: Node) -> None:
        """Whether Webots' renderer lights the world's PBR shapes by a background (image-based
        lighting): a TexturedBackground, or a Background with cube maps."""
        if node.type == "TexturedBackground" or (
                node.type == "Background" and any(self.fields(node).strings(k) for k in BACKGROUND_MAPS)):
            self.image_lit = True

    def unlit_cameras_note(self) -> None:
        """One line when the world's cameras would see only black: no light on anywhere, while Webots
        lights its shapes by the background's image-based lighting (Webots' rosbot.wbt has no light;
        spot.wbt's TexturedBackgroundLight of the "factory" background is off, as Webots has it)."""
        if self.lights_seen or not self.image_lit:
            return
        cameras = [f"{r['name']}/{d['name']}" for r in self.world["robots"] for d in r.get("devices", [])
                   if d.get("device") == "Camera"]
        if cameras:
            listed = ", ".join(cameras[:3]) + (f" and {len(cameras) - 3} more" if len(cameras) > 3 else "")
            self.warnings.append(f"{self.source}: no light is on in this world: its cameras ({listed}) see every "
                                 "surface black; Webots' renderer also lights shapes by the background's "
                                 "image-based lighting (a TexturedBackground's cube map), which is not simulated "
                                 "here: add a DirectionalLight or TexturedBackgroundLight for them to see")

    def scaled_solid(self, node: Node, owner: Owner) -> None:
        """A Solid (a robot, a device, a joint's end point) under a Transform that scales: Webots
        (R2022a+) allows only Transform, Pose, Group and Shape in a Transform, and never scales a
        Solid; dropped as a loss, saying so."""
        t = node.type
        named = node.fields.get("name")
        name = named if isinstance(named, str) else ""
        kind = ("robot" if t == "Robot" else "device" if t in SENSORS or t in OTHER_DEVICES
                else "solid")
        robot = owner.data.get("name", "") if owner.kind == "robot" else ""
        what = f"{t} {name!r}" if name else t
        self.drop(node, f"{what} under a Transform that scales: Webots allows only Transform, Pose, Group and "
                        "Shape in a Transform's children (a Solid, robot or device is never scaled); dropped with "
                        "everything inside it", kind, name, robot)

    def appearance_note(self, node: Node, message: str) -> None:
        if message.startswith("texture: "):   # one summary line for all textures not loaded
            if id(node) not in self.textured:
                self.textured[id(node)] = (node.line, node.col, self.where(node), message[len("texture: "):])
        else:
            self.warn(node, message)

    def def_name(self, node: Node, data: dict) -> None:
        """Keep a robot's, top-level solid's or top-level light's DEF (getFromDef); a DEF reused later keeps its first node."""
        if node.def_name is not None and node.def_name not in self.defs:
            self.defs.add(node.def_name)
            data["def_name"] = node.def_name

    def typos(self, node: Node) -> None:
        if id(node) in self.checked:
            return
        self.checked.add(id(node))
        for name, meant in fx.field_typos(node):
            line, col = node.field_pos.get(name, (node.line, node.col))
            self.warnings.append(f"{self.where(node, (line, col))}: {node.type}.{name}: not a {node.type} field, "
                                 f"ignored (did you mean {meant}?)")

    def stand_in_typos(self, node: Node) -> None:
        """A built-in stand-in's fields outside its PROTO's interface: each one warning at its line (Webots
        skips an unknown PROTO field with an error; the stand-in would silently use the default)."""
        import difflib

        known = BUILTIN_FIELDS[node.type]
        for name in node.fields:
            if name not in known:
                close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.75)
                meant = f" (did you mean {close[0]}?)" if close else ""
                line, col = node.field_pos.get(name, (node.line, node.col))
                self.warnings.append(f"{self.where(node, (line, col))}: {node.type}.{name}: not a field of "
                                     f"PROTO {node.type}, ignored{meant}")

    def child_frame(self, node: Node, frame: Frame, scale: tuple[float, float, float] | None = None) -> Frame:
        """The frame of a Pose, Transform or Solid under ``frame``; ``scale``: a Transform's scale
        as already sanitised (else read here: Webots resets a zero component to 1, with a warning)."""
        f = self.fields(node)
        rotation = f.vec("rotation", (0.0, 0.0, 1.0, 0.0))
        if rotation[3] != 0.0 and math.hypot(*rotation[:3]) == 0.0:
            raise f.error("rotation", "the rotation axis must not be zero")
        if scale is None:
            scale = self.transform_scale(node) if node.type == "Transform" else (1.0, 1.0, 1.0)
        return frame.then(f.vec("translation", (0.0, 0.0, 0.0)), rotation, scale)

    def written_scale(self, node: Node, entry: dict) -> None:
        """A Transform node's ``scale`` as its world file writes it (Webots' reset of a zero component), in
        ``entry`` when not 1 1 1 (the Supervisor's getField of a nested Transform reads it)."""
        scale = self.transform_scale(node)
        if scale != (1.0, 1.0, 1.0):
            entry["scale"] = list(scale)

    def transform_scale(self, node: Node) -> tuple[float, float, float]:
        """A Transform's scale; a zero component is reset to 1 as Webots does (its warning)."""
        f = self.fields(node)
        scale = list(f.vec("scale", (1.0, 1.0, 1.0)))
        for k, axis in enumerate("xyz"):
            if scale[k] == 0.0 and id(node) not in self.checked_scale:
                self.warn(node, f"All 'scale' coordinates must be non-zero: {axis} is set to 1.0.")
            if scale[k] == 0.0:
                scale[k] = 1.0
        self.checked_scale.add(id(node))
        return scale[0], scale[1], scale[2]

    # ------------------------------------------------------------ shapes
    def shape(self, node: Node, frame: Frame, owner: Owner, seen_by: str) -> None:
        f = self.fields(node)
        gnode = f.node_("geometry") if node.type == "Shape" else node
        if gnode is None:
            return
        if gnode.type in UNSEEN_GEOMETRIES:
            self.skipped[gnode.type] += 1
            return
        if gnode.type not in GEOMETRIES:
            self.lose_shape(gnode, f"geometry {gnode.type} is not read here (Box, Sphere, Cylinder, Capsule, Cone, "
                                   "Plane, IndexedFaceSet, Mesh, ElevationGrid): this shape is left out, rays do not "
                                   "see it", owner)
            return
        if gnode.type == "Cone" and seen_by == "bounding":
            self.warn(gnode, "a Cone in a boundingObject: Webots accepts none (no physics geometry); left out, "
                             "bounding rays do not see it (as in Webots)")
            return
        self.tick(gnode)
        for checked in (node, gnode, f.node_("appearance") if node.type == "Shape" else None):
            if checked is not None:
                self.typos(checked)
                material = checked.fields.get("material") if checked.type == "Appearance" else None
                if isinstance(material, Node):
                    self.typos(material)
        geometry, why = self.geometry(gnode, frame, seen_by)
        if geometry is None:
            if why:
                self.lose_shape(gnode, why, owner)
            return
        key = (id(gnode), frame.key())
        if seen_by == "bounding" and key in owner.keys and owner.keys[key]["geometry"] == geometry:
            owner.keys[key]["seen_by"] = "both"     # the same geometry seen by both kinds of ray
            return
        part: dict[str, Any] = {"pose": frame.pose(), "geometry": geometry, "seen_by": seen_by}
        if gnode.type == "IndexedFaceSet" and not self.fields(gnode).flag("ccw", True):
            self.clockwise.add(id(geometry))
        if seen_by == "visual":
            app = fx.appearance(f.node_("appearance"), self.source, self.appearance_note,
                                lambda n, u: self.asset(n, u, "texture"), self.field_reset)
            if app is not None:
                part["appearance"] = app
            if node.type == "Shape" and not f.flag("castShadows", True):
                part["cast_shadows"] = False
            if node.type == "Shape":       # a node a Supervisor serves
                part["node"] = self.shape_node(node, owner)
            owner.keys[key] = part
        part["_at"] = self.at(gnode)
        self.ride(part)
        self.held_by_solid(part, owner)
        owner.parts.append(part)

    def held_by_solid(self, part: dict, owner: Owner) -> None:
        """A robot's shape names the nearest Solid (or device) of the robot's nodes holding it
        (``in_solid``; none: the robot's own), which the Supervisor's contact points report."""
        if owner.kind != "robot" or self.tree is None:
            return
        for _, k in reversed(self.tree_stack):
            t = self.tree[k]["type"]
            if t not in ("Pose", "Transform", "Group", "Slot") and t not in JOINTS:
                part["in_solid"] = k
                return

    def shape_node(self, node: Node, owner: Owner) -> dict:
        """The Supervisor's view of a Shape (schemas.world.ShapeNode): its DEFs and written fields, and
        where it sits among its parent's children (a robot's: after the last tree node written before
        it; a solid's: after its children solids so far)."""
        out = fx.shape_node(node, self.source, self.nested_def,
                            lambda n: self.shared_nodes.setdefault(id(n), len(self.shared_nodes)))
        tags = self.inner_defs(node)
        app = self.fields(node).node_("appearance") if "appearance" in out else None
        if app is not None:
            tags += self.inner_defs(app, "appearance")
            a = self.fields(app)
            if out.get("material"):
                tags += self.inner_defs(a.node_("material"), "material")
            texture = a.node_("texture" if app.type == "Appearance" else "baseColorMap")
            if texture is not None and texture.type == "ImageTexture":
                tags += self.inner_defs(texture, "texture")
        if out.get("geometry"):
            tags += self.inner_defs(self.fields(node).node_("geometry"), "geometry")
        if tags:
            out["inner_defs"] = tags[:64]
        self.written_at(node, out)
        app = self.fields(node).node_("appearance")
        if app is not None and app.proto and "appearance" in out:     # an appearance PROTO (PaintedWood, ...)
            out["appearance_proto"] = app.proto
            face: dict[str, Any] = {}
            self.interface(app, face)
            if face.get("interface"):
                out["appearance_interface"] = face["interface"]
        if owner.kind == "robot" and self.tree is not None:
            if self.tree_stack:
                out["parent"] = self.tree_stack[-1][1]
            out["after"] = len(self.tree) - 1
        elif owner.kind != "robot":
            out["after"] = len(owner.data.get("children", ())) - 1
            self.in_solid_pose(owner, out)
        return out

    def cad_shape(self, node: Node, frame: Frame, owner: Owner) -> None:
        """A CadShape: its file as a visual mesh. A COLLADA file, or an OBJ file with .mtl materials,
        gives one shape per material its triangles use (a Mesh of that material_index), seen in the
        material's diffuse colour, or its diffuse texture through the file's texture coordinates (the
        image's path is relative to the mesh file, as in Webots); other files are seen white."""
        urls = self.fields(node).strings("url")
        if not urls:
            return
        url = urls[0].replace("\\", "/")
        kind = Path(url.split("?")[0]).suffix.lower()[1:]
        materials = self.cad_materials(node, url, kind) if kind in ("dae", "obj") else None
        if materials is None:
            mesh = Node("Mesh", {"url": [url]}, node.line, node.col, source=node.source)
            before = len(owner.parts)
            self.shape(Node("Shape", {"geometry": mesh}, node.line, node.col, source=node.source), frame, owner,
                       seen_by="visual")
            if len(owner.parts) > before:
                owner.parts[-1]["_at"] = self.at(node)      # (a problem with its file names the CadShape)
            return
        where, found = materials
        for index, m in found:
            mesh = Node("Mesh", {"url": [url], "materialIndex": index}, node.line, node.col, source=node.source)
            self.cad_meshes.add(id(mesh))
            before = len(owner.parts)
            self.shape(Node("Shape", {"geometry": mesh}, node.line, node.col, source=node.source), frame, owner,
                       seen_by="visual")
            if len(owner.parts) == before:
                return          # the file is lost (said once)
            owner.parts[-1]["_at"] = self.at(node)
            app: dict[str, Any] = {"base_color": list(m.diffuse), "transparency": m.transparency}
            if m.texture is not None:
                image = self.cad_texture(node, where, m.texture)
                if image is not None:
                    app["texture"] = image
            owner.parts[-1]["appearance"] = app

    def textures_not_loaded(self) -> str:
        """The one line for the textures not loaded (world/textures.py says why each is refused): a world's,
        or a node's a Supervisor imports or builds again."""
        (_, _, where, why), n = min(self.textured.values()), len(self.textured)
        return (f"{where}: {n} texture{'s' if n > 1 else ''} not loaded (first: {why}); "
                "read as Webots reads a texture it cannot load: an Appearance as its material's "
                "diffuseColor, a PBRAppearance as its baseColor"
                + (", an emissiveColorMap as its emissiveColor" if any(
                    why.startswith(fx.GLOW_MAP + ": ") for *_, why in self.textured.values()) else ""))

    def cad_texture(self, node: Node, where: Path, texture: str) -> dict | None:
        """A CadShape material's diffuse image (its path as the file writes it, relative to the file)
        → the world's texture, or None (said once, as other textures not loaded): a PROTO's or
        ``webots://`` file's image is read in place, read only; a world-folder file's must stay in
        that folder."""
        from urllib.parse import unquote

        tex = unquote(texture.replace("\\", "/"))
        tex = tex.removeprefix("file://")
        if where.is_absolute():
            tex_url = str((where.parent / tex).resolve())
            if Path(tex_url).is_file():
                self.asset_files.add(Path(tex_url))
        else:
            tex_url = posixpath.normpath(posixpath.join(posixpath.dirname(where.as_posix()), tex))
            folder = Path(self.source).resolve().parent
            if not (folder / tex_url).resolve().is_relative_to(folder):
                self.appearance_note(node, f"texture: {texture!r} (of {where.as_posix()!r}) is outside the "
                                           "world's folder")
                return None
        return fx.image_texture(Node("ImageTexture", {"url": [tex_url]}, node.line, node.col, source=node.source),
                                self.source, lambda _n, message: self.appearance_note(node, message))

    def cad_materials(self, node: Node, url: str, kind: str) -> tuple[Path, list[tuple[int, Any]]] | None:
        """(the file as the converted world names it, [(material index, CadMaterial)] its triangles
        use) of a CadShape's COLLADA or OBJ file; None when it cannot be read here (then the Mesh it
        becomes says why, as a loss or a problem naming the file) or an OBJ file has no materials."""
        from sensorium.server.world.cad import DEFAULT_MATERIAL
        from sensorium.server.world.meshes import MeshFileError, MeshMemoryError, file_materials

        named, _ = self.asset(node, url)
        if named is None:
            return None
        path = Path(named)
        file = path if path.is_absolute() else Path(self.source).resolve().parent / path
        if (file, kind) not in self.cad_read:
            try:
                self.cad_read[(file, kind)] = file_materials(file, kind)
            except MeshMemoryError as exc:
                # its geometry may still load (--allow-large): then it is seen white, and that is said
                self.appearance_note(node, f"the materials of {url!r} are not read ({exc}): seen white")
                self.cad_read[(file, kind)] = None
            except MeshFileError:         # the Mesh it becomes says why, once
                self.cad_read[(file, kind)] = None
        if self.cad_read[(file, kind)] is None:
            return None
        materials, indices = self.cad_read[(file, kind)]
        used = [(i, materials[i]) for i in indices]
        if kind == "obj" and all(m.name == DEFAULT_MATERIAL for _, m in used):
            return None         # no materials: the file as trimesh reads it, white
        return path, used

    def bounding(self, node: Node | None, frame: Frame, owner: Owner) -> None:
        if node is None:
            return
        self.walk(node)
        f = self.fields(node)
        if node.type in GEOMETRIES or node.type == "Shape":
            self.shape(node, frame, owner, seen_by="bounding")
        elif node.type == "Group":
            for child in f.nodes("children"):
                self.bounding(child, frame, owner)
        elif node.type in ("Pose", "Transform"):
            scale = None
            if node.type == "Transform":     # Webots' physics constraint on the scale over its geometry
                scale, why = bounding_constraint(self.first_geometry(node), self.transform_scale(node))
                if why and id(node) not in self.constrained:
                    self.constrained.add(id(node))
                    self.warn(node, why)
            inner = self.child_frame(node, frame, scale)
            for child in f.nodes("children"):
                self.bounding(child, inner, owner)
        else:
            self.warn(node, f"{node.type} in a boundingObject: ignored")

    def first_geometry(self, node: Node) -> str:
        """The type of a Transform's first child geometry (directly or in a Shape), as Webots looks it up."""
        children = self.fields(node).nodes("children")
        if not children:
            return ""
        first = children[0]
        if first.type == "Shape":
            g = self.fields(first).node_("geometry")
            return g.type if g is not None else ""
        return first.type

    def asset(self, node: Node, url: str, kind: str = "mesh") -> tuple[str | None, str]:
        """The url a converted world names for an asset (``kind``: mesh or texture) ``url`` written in
        ``node``'s file: as written when the world file names a local file (the loader confines it to
        the world's folder); else (a PROTO's url, relative to the PROTO file; ``webots://`` or Webots'
        GitHub urls, from the installation) the local file it names, which must lie in the Webots
        installation, a --proto-path folder or the project of the PROTO file that names it (read
        only). (None, why): the file is missing or refused (the caller says so, naming it)."""
        from sensorium.server.world.meshes import SUPPORTED
        from sensorium.server.world.proto import ProtoError, asset_roots, resolve_url

        src = node.source or self.source
        suffix = Path(url.split("?")[0]).suffix.lower()
        if kind == "mesh" and suffix not in SUPPORTED:
            return None, (f"mesh {url!r}: the {suffix or 'unnamed'} format is not read here "
                          f"({', '.join(sorted(SUPPORTED))}); this shape is left out, rays do not see it")
        if src == self.source and "://" not in url:
            if kind == "texture":
                return url, ""            # checked (and said when missing) where textures are read
            if not (Path(self.source).resolve().parent / url).is_file() and "\0" not in url:
                return None, f"mesh file {url!r} not found (relative to the world file): this shape is left out"
            return url, ""
        lost = "this shape is left out" if kind == "mesh" else "not loaded"
        if self.search is None:
            return None, f"{kind} url {url!r}: no PROTO search places to resolve it; {lost}"
        try:
            path = resolve_url(url, src, self.search).resolve()
        except ProtoError as exc:
            if kind == "texture" and _world_relative(url, self.source):
                # a relative url a PROTO does not hold (a value the world writes for its field, or a
                # Supervisor sets): Webots' WbUrl::computePath looks in the project's protos/ folder, then
                # the world's folder; read there, confined to it as a world file's textures are
                return url, ""
            message = exc.message
            if kind == "texture" and _relative(url):     # the world's folder was looked in too
                message = message.replace("; nothing is downloaded",
                                          f", {Path(self.source).resolve().parent / url}; nothing is downloaded", 1)
            return None, f"{kind} file {message}; {lost}"
        except (OSError, ValueError) as exc:
            return None, f"{kind} url {url!r} cannot be resolved ({exc}); {lost}"
        roots = [*asset_roots(self.search), Path(src).resolve().parent.parent, Path(self.source).resolve().parent]
        if not any(path.is_relative_to(r) for r in roots):
            return None, (f"{kind} url {url!r} names a file outside the Webots installation, the --proto-path "
                          f"folders and the PROTO's project: refused, {lost}")
        if not path.is_file():
            return None, f"{kind} file {url!r} not found: {lost}"
        self.asset_files.add(path)
        return str(path), ""

    def geometry(self, node: Node, frame: Frame, seen_by: str) -> tuple[dict | None, str]:
        """The geometry dict of a geometry node under ``frame``'s scale (``frames.py``: a visual shape
        is the exact affine image, a bounding one what Webots gives ODE); (None, why) when it is
        left out (why: "" when another message was given already)."""
        w = frame.webots_scale
        if frame.stretch is None and frame.scale > 0 and w[0] == w[1] == w[2] > 0:
            return self.base_geometry(node, frame.scale)
        g, why = self.base_geometry(node, 1.0)
        if g is None:
            return None, why
        if seen_by == "bounding":
            return bounding_geometry(g["type"], g, frame.webots_scale), ""
        return visual_geometry(g["type"], g, frame)

    def base_geometry(self, node: Node, s: float) -> tuple[dict | None, str]:
        f = self.fields(node)
        t = node.type
        # sizes Webots resets (each node's sanitizeFields): a non-positive one is 1, a Box's or a
        # Plane's size with any non-positive component all ones
        if t == "Box":
            return {"type": "box", "size": [v * s for v in f.positive_vec("size", (2.0, 2.0, 2.0), (1.0, 1.0, 1.0))]}, ""
        if t == "Sphere":
            return {"type": "sphere", "radius": f.positive("radius", 1.0) * s}, ""
        if t in ("Cylinder", "Capsule"):
            if not all(f.flag(k, True) for k in ("bottom", "side", "top")):
                self.warn_once(node, f"{t} with bottom/side/top FALSE: rays see the whole closed {t.lower()}")
            return {"type": t.lower(), "radius": f.positive("radius", 1.0) * s,
                    "height": f.positive("height", 2.0) * s}, ""
        if t == "Plane":
            return {"type": "plane", "size": [v * s for v in f.positive_vec("size", (1.0, 1.0), (1.0, 1.0))]}, ""
        if t == "Cone":
            if not all(f.flag(k, True) for k in ("bottom", "side")):
                self.warn(node, "Cone with bottom/side FALSE: rays see the whole closed cone")
            return {"type": "cone", "bottom_radius": f.positive("bottomRadius", 1.0) * s,
                    "height": f.positive("height", 2.0) * s}, ""
        if t == "ElevationGrid":
            return self.elevation_grid(node, f, s)
        if t == "Mesh":
            urls = f.strings("url")
            if not urls:
                raise f.error("url", "a Mesh needs a url")
            url, why = self.asset(node, urls[0].replace("\\", "/"))
            if url is None:
                return None, why
            out = {"type": "mesh", "url": url, "scale": [s, s, s]}
            # Webots reads both for COLLADA files only; a CadShape's OBJ materials become Meshes of one material
            if Path(url).suffix.lower() == ".dae" or id(node) in self.cad_meshes:
                if f.integer("materialIndex", -1) >= 0:
                    out["material_index"] = f.integer("materialIndex", -1)
                if f.string("name", ""):
                    out["name"] = f.string("name", "")
            return out, ""
        # IndexedFaceSet: polygons separated by -1, triangulated as Webots' tessellator covers them
        # (convex ones fanned, concave ones cut into ears; texCoordIndex alongside)
        # (points and indices as numpy arrays all the way to the model: 8 bytes a number, no Python object each)
        coord = f.node_("coord")
        points = self.fields(coord).row_array("point", 3) if coord is not None else np.empty((0, 3))
        index = f.index_array("coordIndex")
        lowest = (int(index.min()) if isinstance(index, np.ndarray) else min(index)) if len(index) else 0
        if lowest < -1:
            raise f.error("coordIndex", f"{lowest} is not a vertex index (-1 ends a face)")
        tex, tex_index = fx.tex_coords(node, f, len(index), self.warn)
        cut = self.ear_cut.get(id(node))
        if cut is not None and _same(cut[0], index) and (cut[1] is points or np.array_equal(cut[1], points)):
            corners, fanned = cut[2], cut[3]        # a DEF face USEd again: the same triangles, charged once
        else:
            spent = self.ear_budget[0]
            corners, fanned = polygon_corners(index, points.reshape(-1), self.ear_budget)
            if fanned or self.ear_budget[0] != spent:   # what the budget decided is kept for the next use
                self.ear_cut[id(node)] = (index, points, corners, fanned)
        if fanned:     # said once for the world, at its end (a hostile world has thousands of these nodes)
            self.left_fanned.setdefault(self.where(node), fanned)
        faces = _pick(index, corners)
        tex_faces = _pick(tex_index, corners) if tex_index is not None else []
        if not len(faces):
            raise f.error("coordIndex", "an IndexedFaceSet needs at least one polygon")
        vertices = points * float(s)        # the same products as one at a time (s is a float: the frame's scale)
        out = {"type": "triangles", "vertices": vertices, "faces": faces}
        if tex is not None:
            out["tex_coords"], out["tex_coord_faces"] = tex, tex_faces
        return out, ""

    def elevation_grid(self, node: Node, f: Fields, s: float) -> tuple[dict | None, str]:
        """Webots' ElevationGrid with its sanitising (WbElevationGrid::sanitizeFields, checkHeight):
        a negative thickness → 0, a non-positive spacing → 1, missing heights are 0 and extra ones
        ignored, each with a warning naming the field; fewer than 2 points along x or y is no
        surface (Webots builds none), said. A grid too large is refused before its heights are read."""
        said = id(node) in self.checked_grids
        self.checked_grids.add(id(node))

        def warn(message: str) -> None:
            if not said:
                self.warn(node, message)

        nx, ny = f.integer("xDimension", 0), f.integer("yDimension", 0)
        cap = self.max_grid_points
        for name, n in (("xDimension", nx), ("yDimension", ny)):
            if n > cap:
                raise f.error(name, f"{n:,} points: more than {cap:,} points in one grid are refused "
                                    "(raise the limits with --allow-large)")
        if nx * ny > cap:
            raise f.error("xDimension", f"{nx:,} x {ny:,} = {nx * ny:,} points: more than {cap:,} points in one grid "
                                        "are refused (raise the limits with --allow-large)")
        if nx >= 2 and ny >= 2:
            self.grid_points += nx * ny
            if self.grid_points > cap:
                raise f.error("xDimension", f"the world's ElevationGrids have more than {cap:,} points together "
                                            "(each use of a DEF counts; raise the limits with --allow-large)")
        spacing = {}
        for name in ("xSpacing", "ySpacing"):
            spacing[name] = f.num(name, 1.0)
            if spacing[name] <= 0.0:
                warn(f"ElevationGrid.{name}: {spacing[name]:g} is not positive: reset to 1, as Webots does")
                spacing[name] = 1.0
        thickness = f.num("thickness", 0.0)
        if thickness < 0.0:
            warn(f"ElevationGrid.thickness: {thickness:g} is negative: reset to 0, as Webots does")
            thickness = 0.0
        if nx < 2 or ny < 2:
            warn(f"ElevationGrid with xDimension {nx} and yDimension {ny}: fewer than 2 points along an "
                 "axis is no surface (Webots renders none): nothing to see")
            return None, ""
        height = f.numbers("height")
        need = nx * ny
        if len(height) > need:
            warn(f"ElevationGrid.height: {len(height) - need} extra value(s) ignored ({nx} x {ny} points)")
            height = height[:need]
        elif len(height) < need:
            warn(f"ElevationGrid.height: {len(height)} values for {nx} x {ny} = {need} points: the "
                 f"missing {need - len(height)} are 0, as Webots does")
            height = height + [0.0] * (need - len(height))
        return {"type": "elevation_grid", "height": [h * s for h in height], "x_dimension": nx,
                "x_spacing": spacing["xSpacing"] * s, "y_dimension": ny, "y_spacing": spacing["ySpacing"] * s,
                "thickness": thickness * s}, ""

    # ------------------------------------------------------------ lights
    def light(self, node: Node, frame: Frame, owner: Owner) -> None:
        self.tick(node)
        data = fx.light(node, self.fields(node))
        if data["on"] or id(node) in self.led_of:   # (an LED's lights are off until it is set)
            self.lights_seen += 1
        if wm.light_value_problem("color", data["color"]) is not None:     # WbLight::updateColor
            self.warn(node, f"{node.type} color {' '.join(f'{c:g}' for c in data['color'])} clamped to [0, 1] "
                            "(Webots resets it)")
            data["color"] = [min(max(c, 0.0), 1.0) for c in data["color"]]
        written = {k: list(data[k]) for k in ("location", "direction") if k in data}
        if "location" in data:
            data["location"] = frame.apply(data["location"])
        if node.type == "SpotLight":
            field = np.asarray(data["direction"])
            data["direction"] = [float(v) for v in frame.rotation @ field]    # as the renderer turns it
            if frame.own_rotation is not None:    # WbLightSensor: turned by the nearest Pose's own rotation only
                aim = [float(v) for v in frame.own_rotation @ field]
                if owner.kind != "world" or aim != data["direction"]:
                    data["light_sensor_direction"] = aim
        data["_at"] = self.at(node)
        if owner.kind == "world":
            self.def_name(node, data)
        else:                     # (an LED's too: the scene places its lights in the robot's frame)
            self.light_node(node, frame, owner, data, written)
        led = self.led_of.get(id(node))
        if led is not None:       # switched by an LED: in the LED's frame, in its lights
            entry, at = led
            back = at.rotation.T
            if "location" in data:
                data["location"] = [float(v) for v in back @ (np.asarray(data["location"]) - at.translation)]
            if node.type == "SpotLight":
                data["direction"] = [float(v) for v in back @ np.asarray(data["direction"])]
            entry.setdefault("lights", []).append(data)
            return
        if owner.kind == "robot":     # a robot's light past a joint rides on it (an LED's ride with the LED)
            self.ride(data)
        owner.data.setdefault("lights", []).append(data) if owner.kind != "world" else self.world["lights"].append(data)

    def light_node(self, node: Node, frame: Frame, owner: Owner, data: dict, written: dict) -> None:
        """A light inside a robot or solid as the Supervisor node it is (schemas.world.LightNode): its DEF,
        its place among its parent's children, its parent's frame and its fields as written. One under a
        scaled Transform keeps the scale (``linear``) that places a location set; its parent is the nearest
        node above it, as a Shape's (a scaled Transform is no node inside a solid, nor is a Pose under one)."""
        if owner.kind == "robot" and self.tree is None:
            return
        entry: dict[str, Any] = {"frame": frame.pose(), **written}
        if not frame.rigid:
            entry["linear"] = [float(v) for v in frame.linear().ravel()]
        if "light_sensor_direction" in data and frame.own_rotation is not None:
            entry["aim"] = {"quaternion": list(matrix_quaternion(frame.own_rotation))}
        if owner.kind == "robot":
            assert self.tree is not None
            if self.tree_stack:
                entry["parent"] = self.tree_stack[-1][1]
            entry["after"] = len(self.tree) - 1
        else:
            entry["after"] = len(owner.data.get("children", ())) - 1
            self.in_solid_pose(owner, entry)
        tags = self.inner_defs(node)
        if tags:
            entry["inner_defs"] = tags[:64]
        if not self.written(node):
            entry["body"] = True
        self.written_at(node, entry)
        if self.nested_def(node):
            data["def_name"] = node.def_name
        data["node"] = entry

    def led_lights(self, node: Node) -> list[Node]:
        """The lights an LED switches (``WbLed::findMaterialsAndLights``): only its first child counts; a
        PointLight or SpotLight there, or every one inside it at any depth when it is a Group, Pose,
        Transform or Solid (Webots' groups)."""
        def inside(n: Node) -> list[Node]:
            if n.type in ("PointLight", "SpotLight"):
                return [n]
            if n.type in ("Group", "Pose", "Transform", "Solid"):
                return [lt for child in self.fields(n).nodes("children") for lt in inside(child)]
            return []
        children = self.fields(node).nodes("children")
        return inside(children[0]) if children else []

    # ------------------------------------------------------------ solids and robots
    def battery_values(self, node: Node, what: str) -> list[float]:
        """A Robot's or Charger's battery field: its first three values (energy J, maximum J, speed W);
        none when one of them is negative or not finite (one warning)."""
        values = self.fields(node).numbers("battery") if "battery" in node.fields else []
        if len(values) > 3:
            self.warn(node, f"{what}: battery has {len(values)} values; the first three are used "
                            "(energy, maximum energy, recharge speed)")
            values = values[:3]
        if any(not math.isfinite(v) or v < 0 for v in values):
            self.warn(node, f"{what}: battery {', '.join(f'{v:g}' for v in values)} has a negative or infinite "
                            "value; no battery")
            return []
        return values

    def solid(self, node: Node, frame: Frame, owner: Owner, default: str = "solid", bounding: bool = True) -> dict | None:
        """A Solid (``default``: its name when it has none: a device's default name); its entry (None
        when it is part of a robot's body). ``bounding`` False: its boundingObject is left out (a
        Fluid's: the volume immersed solids float in, which nothing collides with)."""
        f = self.fields(node)
        inner = self.child_frame(node, frame)
        # an empty name (Webots' radar sample's target boxes: name "") is the default one: names here
        # address solids and label radar targets
        name = f.string("name", default) or default
        if owner.kind == "robot":   # part of the robot's body
            target = self.carried_target(node, name, inner, owner)
            start = len(owner.parts)
            self.solid_contents(node, inner, owner, bounding)
            if target is not None:
                target["_members"] = [id(p) for p in owner.parts[start:]]
            return None
        data = {"name": self.unique_name(name) if owner.kind == "world" else name, "pose": inner.pose()}
        if owner.kind == "world":
            self.def_name(node, data)
        elif self.nested_def(node):     # a nested solid: found by DEF (a Supervisor walks it)
            data["def_name"] = node.def_name
        if owner.kind == "solid":       # inside a top-level solid: a node a Supervisor walks
            self.in_solid_pose(owner, data, "in_pose")
            tags = self.inner_defs(node)
            if tags:
                data["inner_defs"] = tags[:64]
            self.written_at(node, data)
        if owner.kind == "world":
            colors = f.colors("recognitionColors", [])        # what cameras with a Recognition node report
            if colors:
                data["recognition_colors"] = [list(c) for c in colors]
            if f.string("model", ""):
                data["model"] = f.string("model", "")
            self.radar_cross_section(node, data)
            if f.node_("physics") is not None:      # what a VacuumGripper may carry
                data["physics"] = True
        elif f.has("recognitionColors") and f.rows("recognitionColors", 3, []):
            self.warn(node, f"Solid {name!r}: recognitionColors of a nested solid are not read (give them to the "
                            "top-level solid); ignored")
        if owner.kind != "world":       # a solid inside a top-level solid: a radar target of its own
            self.radar_cross_section(node, data)
        data.update(solid_mass(self, node))     # the Supervisor's getCenterOfMass
        if owner.kind == "world" and data["name"] != name:
            self.warn(node, f"solid name {name!r} used before: renamed {data['name']!r}")
        mine = Owner("solid", data, placed=owner.placed.compose(inner))
        # a nested solid's spot lights: a LightSensor turns them by this solid's own rotation (not the Poses above)
        own = Frame.identity() if owner.kind == "world" else Frame(np.eye(3), np.zeros(3), own_rotation=inner.own_rotation)
        saved_owner = self.inner_owner
        if owner.kind == "world":
            self.inner_owner = data
            self.open_scope(node, -1)
        elif owner.kind == "solid" and self.scopes and self.scopes[-1].node is node:
            data["proto_scope"] = self.scope_serial
            self.open_scope(node, self.scope_serial)
            self.scope_serial += 1
        try:
            self.solid_contents(node, own, mine, bounding)
        finally:
            self.inner_owner = saved_owner
        out = self.solid_dict(mine, data)
        out["_at"] = self.at(node)
        if owner.kind == "world":
            self.drop_seq(out)
            self.world["solids"].append(out)
        else:
            owner.data.setdefault("children", []).append(out)
        return out

    def marker(self, node: Node, frame: Frame) -> bool:
        """A Pose or Transform (not scaled) with only shapes inside it, through Poses, Transforms and Groups."""
        return self.child_frame(node, frame).rigid and self.shapes_only(node)

    def shapes_only(self, node: Node) -> bool:
        """Only shapes inside ``node``, through Poses, Transforms and Groups (a visual node of its own)."""
        stack = list(self.fields(node).nodes("children"))
        while stack:
            child = stack.pop()
            if child.type in ("Pose", "Transform", "Group"):
                stack += self.fields(child).nodes("children")
            elif child.type not in ("Shape", "CadShape"):
                return False
        return True

    def radar_cross_section(self, node: Node, data: dict) -> None:
        """A solid's or robot's radarCrossSection: > 0 makes it a Radar target (0 or less:
        not one, as in Webots, which keeps a negative value and ignores it)."""
        rcs = self.fields(node).num("radarCrossSection", 0.0)
        if rcs > 0.0:
            data["radar_cross_section"] = rcs

    def carried_target(self, node: Node, name: str, frame: Frame, owner: Owner) -> dict | None:
        """A Solid (or device) inside a robot with a radarCrossSection > 0: a radar target of its own, as
        in Webots (its radar sample: a small target box on each robot), at its origin (``frame``, in the
        robot's) on the joint it rides; its shapes are those found inside it (``_members``, made
        indices by ``carried_shapes``)."""
        rcs = self.fields(node).num("radarCrossSection", 0.0)
        if rcs <= 0.0:
            return None
        target: dict[str, Any] = {"name": name, "pose": frame.pose(), "radar_cross_section": rcs, "_members": []}
        self.ride(target)
        owner.data.setdefault("radar_targets", []).append(target)
        return target

    def display_screen(self, node: Node, owner: Owner, start: int, device: dict) -> None:
        """The shape whose texture a Display's image replaces, as WbDisplay finds it: its first child, or
        that child's first child while it is a Group (a Pose, a Transform), must be a Shape whose
        appearance has an ImageTexture (an Appearance's texture, a PBRAppearance's baseColorMap or
        emissiveColorMap; its url may be empty). Kept as ``_screen`` (its part, made an index in the
        robot's shapes by :meth:`carried_shapes`)."""
        child = next(iter(self.fields(node).nodes("children")), None)
        while child is not None and child.type in ("Group", "Pose", "Transform"):
            child = next(iter(self.fields(child).nodes("children")), None)
        if child is None or child.type != "Shape":
            return
        look = self.fields(child).node_("appearance")
        if look is None or not any(isinstance(look.fields.get(k), Node)
                                   for k in ("texture", "baseColorMap", "emissiveColorMap")):
            return
        geometry = self.fields(child).node_("geometry")
        added = {id(p) for p in owner.parts[start:]}
        made = [p for k, p in owner.keys.items() if geometry is not None and k[0] == id(geometry) and id(p) in added]
        if made:                # (none: its geometry was left out, with its own line)
            device["_screen"] = id(made[0])
            # the maps WbDisplay replaces: each ImageTexture present, a url or none (the appearance keeps
            # only those it loaded, so one without url would be missed, or the base given an image it lacks)
            device["screen_maps"] = [m for m, keys in (("texture", ("texture", "baseColorMap")),
                                                       ("emissive_map", ("emissiveColorMap",)))
                                     if any(isinstance(look.fields.get(k), Node) for k in keys)]
            for k in ("texture", "baseColorMap", "emissiveColorMap"):    # the display's image replaces them:
                texture = look.fields.get(k)                              # one not loaded (no url) is no loss
                if isinstance(texture, Node):
                    self.textured.pop(id(texture), None)

    @staticmethod
    def carried_shapes(robot: dict, parts: list[dict]) -> None:
        """Each carried radar target's shapes, and each Display's screen shape, as indices in the
        robot's final ``shapes``."""
        index = {id(p): k for k, p in enumerate(parts)}
        for target in robot.get("radar_targets", ()):
            target["shapes"] = sorted({index[m] for m in target.pop("_members") if m in index})
        for device in robot.get("devices", ()):
            if "_screen" in device:
                screen = index.get(device.pop("_screen"))
                if screen is not None:
                    device["screen_shape"] = screen

    def solid_contents(self, node: Node, frame: Frame, owner: Owner, bounding: bool = True) -> None:
        f = self.fields(node)
        for k, child in enumerate(f.nodes("children")):
            self.visit(child, frame, owner)
            if k == 0 and node.type == "Charger" and owner.kind == "solid":   # its first child's shapes glow
                owner.data["_glow_shapes"] = len(owner.parts)          # (and its lights, and the solids in it)
                owner.data["_glow_lights"] = len(owner.data.get("lights", []))
                owner.data["_glow_solids"] = len(owner.data.get("children", []))
        if bounding:
            self.bounding(f.node_("boundingObject"), frame, owner)

    def solid_dict(self, owner: Owner, data: dict) -> dict:
        if owner.parts:
            data["shapes"] = [_clean_part(p) for p in owner.parts]
        return data

    def robot(self, node: Node, frame: Frame) -> None:
        f = self.fields(node)
        inner = self.child_frame(node, frame)
        name = f.string("name", "robot")
        if "/" in name:      # a robot's name is one segment of its topic paths (ABB's 'IRB 4600/40')
            segment = name.replace("/", "_")
            self.warn(node, f"robot name {name!r} holds '/', which topic paths cannot: renamed {segment!r} "
                            "(getName() reads it)")
            name = segment
        unique = self.unique_robot(name)
        if unique != name:
            self.warn(node, f"robot name {name!r} used before: renamed {unique!r}")
        self.robot_frames[unique] = inner
        data: dict[str, Any] = {"name": unique, "pose": inner.pose(),
                                "synchronization": f.flag("synchronization", True), "devices": []}
        self.def_name(node, data)
        controller = f.string("controller", "<extern>")
        if controller in ("", "void"):                      # Webots' other ways of saying "no controller"
            controller = "<none>"
        if not controller.startswith("<") and (controller in (".", "..") or any(c in controller for c in "/\\\0")):
            self.warn(node, f"Robot {unique!r}: controller {controller!r} is no controller's name (a folder under "
                            "controllers/): the robot has Webots' <generic> controller (none under sensorium run, "
                            "an <extern> one under serve)")
            controller = "<generic>"
        elif controller.startswith("<") and controller not in ("<extern>", "<none>", "<generic>"):
            self.warn(node, f"Robot {unique!r}: controller {controller!r} is unknown: the robot has Webots' <generic> "
                            "controller (none under sensorium run, an <extern> one under serve)")
            controller = "<generic>"
        # a named controller is kept: `sensorium run` starts it, `sensorium serve` waits for it as <extern>
        extras = {"controller": controller, "controller_args": f.strings("controllerArgs"),
                  "supervisor": f.flag("supervisor", False),
                  "custom_data": f.string("customData", ""), "model": f.string("model", "")}
        defaults: dict[str, Any] = {"controller": "<extern>", "controller_args": [], "supervisor": False,
                                    "custom_data": "", "model": ""}
        for key, value in extras.items():
            if key in self.robot_fields:
                if (key != "controller" or f.has("controller")) and (key != "controller_args" or value):
                    data[key] = value
            elif value != defaults[key]:
                self.warn(node, f"Robot field {key}: not supported by this version; ignored")
        colors = f.colors("recognitionColors", [])
        if colors:
            data["recognition_colors"] = [list(c) for c in colors]
        self.radar_cross_section(node, data)
        data.update(solid_mass(self, node))     # the Supervisor's getCenterOfMass
        if f.flag("selfCollision", False):    # its generic, sonar and laser sensors see its own bounding objects
            data["self_collision"] = True
        battery = self.battery_values(node, f"Robot {unique!r}")
        if battery:        # Webots: current energy, maximum, recharge speed; its battery sensor reads the first
            data["battery"] = battery
            if f.node_("physics") is not None and _consuming_motors(node):
                self.warn(node, f"Robot {unique!r}: its motors' energy consumption (torque x consumptionFactor) is "
                                "not simulated (no torques here): its battery drains by cpuConsumption only")
        if "cpuConsumption" in node.fields:
            data["cpu_consumption"] = f.non_negative("cpuConsumption", 10.0, 10.0)
        data["_at"] = self.at(node)
        mine = Owner("robot", data)
        self.riding = []
        saved = self.tree, self.tree_stack, self.inner_owner
        self.tree, self.tree_stack, self.inner_owner = [], [], data
        self.open_scope(node, -1)
        try:
            self.solid_contents(node, Frame.identity(), mine)
            tree = self.tree
        finally:
            self.tree, self.tree_stack, self.inner_owner = saved
        self.drive(node, mine)
        if mine.parts:
            data["shapes"] = [_clean_part(p) for p in mine.parts]
        self.carried_shapes(data, mine.parts)
        self.unique_devices(data)
        self.tree_done(data, tree)
        for part in data.get("shapes", ()):      # the device's final name (after unique_devices)
            if "_device" in part:
                part["of_device"] = part.pop("_device")["name"]
        self.on_joints(data)
        turn_meshes_away(data, self.clockwise)
        self.devices_inside(data)
        if not data["devices"]:
            del data["devices"]
        self.world["robots"].append(data)
        self.world["robots"].extend(self.riders.pop(unique, ()))

    def devices_inside(self, robot: dict) -> None:
        """One warning for each visual device whose origin is inside one of its robot's closed
        primitives, which Webots never sees from there and rays here do (wbt/inside.py; a mesh is
        split instead: turn_meshes_away). Said once for a primitive listed twice (a body's visual
        shape and its bounding object, the same cylinder where the same line wrote them)."""
        for dev in robot["devices"]:
            where = self.device_where.get(id(dev))
            if where is None:
                continue
            said: set[str] = set()
            for part in enclosing_shapes(robot, dev):
                line, col, _ = part.get("_at", (0, 0, ""))
                at = f" (written at line {line}, column {col})" if line else ""
                text = (f"{where}: {dev['device']} {dev['name']!r} of robot {robot['name']!r} is inside the robot's "
                        f"{part['geometry']['type']}{at}: its rays see that shape from inside, where Webots' never do "
                        "(back faces culled); mount the device outside it or make the shape part of the device's Solid")
                if text not in said:
                    said.add(text)
                    self.warnings.append(text)

    def unique_devices(self, robot: dict) -> None:
        """Device names address topics and services, so a repeated one gets a suffix (Webots warns
        and its getDevice returns the first); the wheel motors' names count too."""
        listed = {d["name"] for d in robot["devices"] if d["device"] in MOTORS}
        seen: Counter[str] = Counter(v for v in drive_motor_names(robot) if v not in listed)
        for dev in robot["devices"]:
            name = dev["name"]
            seen[name] += 1
            if seen[name] > 1:
                new, k = name, seen[name] - 1
                while new in seen:
                    new, k = f"{name}({k})", k + 1
                seen[new] += 1
                dev["name"] = new
                line, col, _ = dev["_at"]
                self.warnings.append(f"{self.source}:{line}:{col}: device name {name!r} used before in robot "
                                     f"{robot['name']!r}: renamed {new!r}")

    def device(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        if owner.kind != "robot":
            self.warn(node, f"{node.type} outside a Robot: not a device here (devices belong to robots); its "
                            "shapes are kept as a solid")
            self.solid(node, frame, owner, fx.DEVICE_NAMES.get(node.type, node.type.lower()))
            return
        self.tick(node)
        inner = self.child_frame(node, frame)
        if node.type in MOTORS:   # a motor outside a joint's device list
            self.warn(node, f"{node.type} outside a joint: skipped")
            return
        if node.type not in self.device_kinds:
            self.drop(node, f"{node.type}: device kind not supported by this version; skipped", "device",
                      f.string("name", node.type), owner.data["name"])
        else:
            data = {"name": f.string("name", fx.DEVICE_NAMES[node.type]), "pose": inner.pose(), **fx.device(node, f)}
            model = f.string("model", "")
            if model:
                data["model"] = model
            data["_at"] = self.at(node)
            self.device_where[id(data)] = self.where(node)
            if node.type == "Lidar" and f.node_("rotatingHead") is not None:
                self.skipped["Lidar.rotatingHead"] += 1
            mask = f.string("noiseMaskUrl", "") if node.type == "Camera" else ""
            if mask and data.get("projection", "planar") != "planar":   # WbWrenCamera::setNoiseMask's refusal
                self.warn(node, f"Camera {data['name']!r}: noiseMaskUrl: Webots applies a noise mask to planar "
                                "cameras only; this spherical camera has none")
            elif mask:
                url, why = self.asset(node, mask, "texture")
                if url is None:
                    self.warn(node, f"Camera {data['name']!r}: noiseMaskUrl: {why}")
                else:
                    data["noise_mask_url"] = url
            for name, what in unread_image_fields(node.type, node.fields):
                self.warn(node, f"{node.type} {data['name']!r} of robot {owner.data['name']!r}: {name} ({what}) is "
                                "not rendered here; the image is Webots' without it")
            self.ride(data)
            owner.data["devices"].append(data)
            self.tree_device(node, data)
            if node.type == "LED":
                self.led_of.update((id(lt), (data, inner)) for lt in self.led_lights(node))
            self.device_contents(node, inner, owner, data)
            return
        self.device_contents(node, inner, owner, None)

    def device_contents(self, node: Node, frame: Frame, owner: Owner, device: dict | None) -> None:
        """A device's own Solid contents: robot body shapes marked as the device's own (its visual
        rays do not see them, sim/own_shapes.py), the innermost device's for nested ones. A device is a
        Solid too: its radarCrossSection makes it a radar target its robot carries."""
        name = device["name"] if device is not None else self.fields(node).string("name", node.type.lower())
        target = self.carried_target(node, name, frame, owner) if owner.kind == "robot" else None
        start = len(owner.parts)
        self.device_depth += 1
        try:
            self.solid_contents(node, frame, owner)
        finally:
            self.device_depth -= 1
        if target is not None:
            target["_members"] = [id(p) for p in owner.parts[start:]]
        if device is not None:
            for part in owner.parts[start:]:
                part.setdefault("_device", device)

    def unsimulated(self, node: Node, frame: Frame, owner: Owner) -> dict:
        """A device listed (its index, type, name and model are Webots') but not simulated here."""
        f = self.fields(node)
        t = node.type
        data: dict[str, Any] = {"name": f.string("name", OTHER_NAMES.get(t, t.lower())), "device": t}
        if "model" in node.fields:
            model = f.string("model", "")
            if model:
                data["model"] = model
        if frame.pose() != {"translation": [0.0, 0.0, 0.0]}:
            data["pose"] = frame.pose()
        if t not in wm.UNSIMULATED_DEVICE_TYPES:       # a kind simulated here: its own fields, by their names
            data.update(self.device_fields(node))
        data["_at"] = self.at(node)
        self.ride(data)
        owner.data["devices"].append(data)
        self.tree_device(node, data)
        return data

    def device_fields(self, node: Node) -> dict[str, Any]:
        """The fields of a device node that its world-file model has (Webots' camelCase names in
        snake_case: ``noiseCorrelation`` → ``noise_correlation``; ``lookupTable`` as rows); a field
        written that the model does not have is said (it is not read)."""
        f = self.fields(node)
        model = getattr(wm, node.type, None)
        known = set(getattr(model, "model_fields", {})) - {"name", "model", "pose", "device"}
        out: dict[str, Any] = {}
        for written, value in node.fields.items():
            key = "".join(f"_{c.lower()}" if c.isupper() else c for c in written)
            if key in known:
                out[key] = ([list(r) for r in f.rows(written, 3, [])] if key == "lookup_table"
                            else list(value) if isinstance(value, tuple) else value)
            elif written not in SOLID_FIELDS:
                self.warn(node, f"{node.type}.{written}: not read here (the device takes its default)")
        return out

    def joint_devices(self, node: Node, owner: Owner, field_name: str = "device") -> tuple[list[dict], list[dict]]:
        """A joint's devices in its ``device`` (or a Hinge2Joint's ``device2``, a BallJoint's ``device2``
        and ``device3``) order (Webots lists
        them before the end point's): (motor entries, position sensor entries). A motor's entry
        carries its fields and the joint's position (a drive keeps only its wheels' names, see
        :meth:`drive`); the joint's sensors measure its motor."""
        motors, sensors, brakes = [], [], []
        params_field = {"device2": "jointParameters2", "device3": "jointParameters3"}.get(field_name, "jointParameters")
        params = self.fields(node).node_(params_field) if node.type.endswith("Joint") else None
        position = self.fields(params).num("position", 0.0) if params is not None else 0.0
        for d in self.fields(node).nodes(field_name):
            self.walk(d)
            self.tick(d)
            entry: dict | None = None
            if d.type in MOTORS:
                entry = {"name": self.fields(d).string("name", OTHER_MOTOR_NAMES[d.type]), "device": d.type,
                         **self.motor_fields(d, position), "_at": self.at(d)}
                self.ride(entry)
                owner.data["devices"].append(entry)
                motors.append(entry)
                if wm.coupling_group(entry["name"]) is not None:   # a drive's wheel is told (see drive())
                    self.coupled_nodes[id(entry)] = d
            elif d.type == "PositionSensor":
                sf = self.fields(d)
                entry = {"name": sf.string("name", "position sensor"), "device": "PositionSensor",
                         "noise": sf.num("noise", 0.0), "resolution": sf.num("resolution", -1.0), "_at": self.at(d)}
                owner.data["devices"].append(entry)
                sensors.append(entry)
            elif d.type == "Brake":
                entry = self.unsimulated(d, Frame.identity(), owner)
                brakes.append(entry)
            else:
                self.warn(d, f"{d.type} in a joint's device list: ignored")
            if entry is not None and self.tree is not None and owner.kind == "robot":   # a node of the joint's
                self.tree_entry(d, {"type": d.type, "_device": entry}, field_name)       # (no Pose: no position)
        for entry in sensors:       # with a motor, its joint's; without, the still joint's position
            if motors:
                entry["motor"] = motors[0]["name"]
            elif position:
                entry["position"] = position
        for entry in brakes:        # a brake names its joint's motor and sensor; a slider's is linear
            linear = node.type == "SliderJoint" or (motors and motors[0]["device"] == "LinearMotor")
            if linear:
                entry["joint_type"] = "linear"
            if motors:
                entry["motor"] = motors[0]["name"]
            if sensors:
                entry["position_sensor"] = sensors[0]["name"]
        return motors, sensors

    def motor_fields(self, d: Node, position: float) -> dict[str, float]:
        """A motor's fields that differ from Webots' defaults, in the world file's names, with the
        resets WbMotor applies (a negative maxVelocity made positive, a negative acceleration other
        than -1 made -1, a negative maxTorque/maxForce 10, limits widened to the joint's position)."""
        f = self.fields(d)
        velocity = f.num("maxVelocity", 10.0)
        if velocity < 0:
            velocity = f.used("maxVelocity", velocity, -velocity, "is negative")
        acceleration = f.num("acceleration", -1.0)
        if acceleration < 0 and acceleration != -1:
            acceleration = f.used("acceleration", acceleration, -1.0, "is negative")
        force_field = "maxTorque" if d.type == "RotationalMotor" else "maxForce"
        force = f.non_negative(force_field, 10.0, 10.0)
        lo, hi = f.num("minPosition", 0.0), f.num("maxPosition", 0.0)
        if lo or hi:                 # limited: they hold the joint's position (enforceMotorLimitsInsideJointLimits)
            if hi < position:
                hi = f.used("maxPosition", hi, position, "is below the joint's position")
            if lo > position:
                lo = f.used("minPosition", lo, position, "is above the joint's position")
        multiplier = f.num("multiplier", 1.0)
        if multiplier == 0.0:         # WbMotor::updateMultiplier
            multiplier = f.used("multiplier", multiplier, 1.0, "cannot be 0")
        out = {"max_velocity": velocity, "min_position": lo, "max_position": hi, "acceleration": acceleration,
               "max_torque" if d.type == "RotationalMotor" else "max_force": force, "position": position,
               "multiplier": multiplier}
        defaults = {"max_velocity": 10.0, "min_position": 0.0, "max_position": 0.0, "acceleration": -1.0,
                    "max_torque": 10.0, "max_force": 10.0, "position": 0.0, "multiplier": 1.0}
        return {k: v for k, v in out.items() if v != defaults[k]}

    def ride(self, entry: dict) -> None:
        """A robot's shape or device (or a joint's motor) found inside a joint's end point rides on
        that joint, the innermost one (its motor's entry, named once names are final: ``on_joints``)."""
        if self.riding:
            entry["_on_joint"] = self.riding[-1]

    def joint_frame(self, node: Node, frame: Frame, entry: dict) -> None:
        """A HingeJoint's axis and anchor, a SliderJoint's axis, from its parent Solid's frame into
        the robot's (``frame``: the joint's place in the robot), on ``entry``: its motor's, its node's."""
        params = self.fields(node).node_("jointParameters")
        pf = self.fields(params) if params is not None else None
        default = (1.0, 0.0, 0.0) if node.type == "HingeJoint" else (0.0, 0.0, 1.0)
        axis = pf.vec("axis", default) if pf else default
        entry["axis"] = [float(v) for v in frame.rotation @ np.asarray(axis, dtype=np.float64)]
        if node.type == "HingeJoint":
            anchor = pf.vec("anchor", (0.0, 0.0, 0.0)) if pf else (0.0, 0.0, 0.0)
            entry["anchor"] = [float(v) for v in frame.apply(anchor)]

    def joint(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        end = f.node_("endPoint")
        motors = [d for d in f.nodes("device") if d.type in MOTORS]
        sensors: list[dict] = []
        moving: list[dict] = []
        spin_sensors: list[dict] = []
        if owner.kind == "robot":
            moving, sensors = self.joint_devices(node, owner)
            if node.type == "Hinge2Joint":      # its second axis's devices follow its first's (Webots' order)
                spin, spin_sensors = self.joint_devices(node, owner, "device2")
                moving = self.hinge2_frames(node, frame, moving[:1], spin[:1])
            elif node.type == "BallJoint":
                second, _ = self.joint_devices(node, owner, "device2")
                third, _ = self.joint_devices(node, owner, "device3")
                motors += [d for field_ in ("device2", "device3") for d in f.nodes(field_) if d.type in MOTORS]
                moving = self.ball_frames(node, frame, moving[:1], second[:1], third[:1])
            elif node.type not in ("HingeJoint", "SliderJoint"):
                moving = []
            elif moving:
                self.joint_frame(node, frame, moving[0])
        # a joint inside a device (a lidar's spinning turret, a camera's pan-tilt) moves the device,
        # never the robot: it is no wheel, whatever its axis (Webots has no notion of a drive either)
        wheeled = owner.kind == "robot" and not self.device_depth
        if wheeled and node.type == "Hinge2Joint":    # a steered wheel (a car)
            self.hinge2(node, frame, owner, motors, sensors, spin_sensors)
        elif wheeled and node.type == "HingeJoint" and motors:
            params = f.node_("jointParameters")
            if params is not None:
                self.typos(params)
            pf = self.fields(params) if params is not None else None
            axis = pf.vec("axis", (1.0, 0.0, 0.0)) if pf else (1.0, 0.0, 0.0)
            anchor = pf.vec("anchor", (0.0, 0.0, 0.0)) if pf else (0.0, 0.0, 0.0)
            m = self.fields(motors[0])
            centre = anchor
            wheel = self.slotted(end)
            if wheel is not None and wheel.type == "Solid":
                centre = self.fields(wheel).vec("translation", (0.0, 0.0, 0.0))
            turn = frame.rotation @ np.asarray(axis)
            owner.wheels.append({"node": node, "motor": m.string("name", "rotational motor"),
                                 "steers": abs(turn[2]) > 0.9 * float(np.linalg.norm(turn)),   # a vertical axis
                                 "max_velocity": m.num("maxVelocity", 10.0), "limits": _limits(m),
                                 "axis": frame.rotation @ np.asarray(axis), "anchor": np.asarray(frame.apply(anchor)),
                                 "centre": np.asarray(frame.apply(centre)),
                                 "end": end, "frame": frame, "sensors": sensors})
        elif motors and (node.type != "Hinge2Joint" or not wheeled) and owner.kind == "robot":
            if wheeled:       # a slider or a ball joint is never a wheel: the motor by name, as a hinge's
                names = ", ".join(repr(self.fields(m).string("name", OTHER_MOTOR_NAMES[m.type])) for m in motors)
                self.warn(node, f"{node.type} motor {names}: {JOINT_MOVES}")
            else:
                self.warn(node, f"{node.type} motor(s) not part of a wheel (inside a device): {JOINT_MOVES}")
        elif motors:
            self.warn(node, f"{node.type} motor(s) outside a robot: not simulated")
        # (a robot's Hinge2Joint: hinge2() said which of its axes has sensors but no motor)
        if not motors and wheeled and node.type == "HingeJoint":     # perhaps a car's free rear wheel
            line = (f"PositionSensor on a joint without a motor: reads the joint's position, "
                    f"{sensors[0].get('position', 0.0):g} (nothing turns the joint here)") if sensors else None
            pf = self.fields(f.node_("jointParameters")) if f.node_("jointParameters") is not None else None
            axis = pf.vec("axis", (1.0, 0.0, 0.0)) if pf else (1.0, 0.0, 0.0)
            centre = anchor = pf.vec("anchor", (0.0, 0.0, 0.0)) if pf else (0.0, 0.0, 0.0)
            wheel = self.slotted(end)
            if wheel is not None and wheel.type == "Solid":
                centre = self.fields(wheel).vec("translation", (0.0, 0.0, 0.0))
            owner.free.append({"node": node, "sensors": sensors, "line": line, "steer": None,
                               "axis": frame.rotation @ np.asarray(axis), "anchor": np.asarray(frame.apply(anchor)),
                               "centre": np.asarray(frame.apply(centre)), "end": end, "frame": frame})
        elif sensors and not motors and node.type != "Hinge2Joint":
            self.warn(node, f"PositionSensor on a joint without a motor: reads the joint's position, "
                            f"{sensors[0].get('position', 0.0):g} (nothing turns the joint here)")
        if end is not None:
            if end.type == "SolidReference":      # a closed chain (a parallel gripper's linkage): Webots'
                # physics closes it; here the joint is left out, so the Solid named moves only with
                # the joints it is written in (a parallelogram's finger turns with its driven link)
                name = self.fields(end).string("solidName", "")
                if name == "<static environment>":      # Webots ties the Solid above the joint to the world
                    self.warn(node, f"{node.type} ending in SolidReference {name!r}: the Solid above it is not tied "
                                    "to the world here (no physics); the joint is left out")
                elif not name:
                    self.warn(node, f"{node.type} ending in a SolidReference without a solidName: it names no Solid; "
                                    "the joint is left out")
                elif not self.names_a_solid(name):
                    self.warn(node, f"{node.type} ending in SolidReference {name!r}: no Solid is named {name!r} in "
                                    "the robot or solid it is written in (Webots refuses the reference); the joint "
                                    "is left out")
                else:
                    self.warn(node, f"{node.type} ending in SolidReference {name!r}: the loop it closes is not "
                                    f"closed here (no physics); {name!r} moves with the joints it is written in only")
                return
            self.tree_field = "endPoint"
            if moving:          # what the end point holds rides on this joint (its innermost motor's)
                self.riding.append(moving[-1])
            try:
                self.visit(end, frame, owner)
            finally:
                if moving:
                    self.riding.pop()

    def names_a_solid(self, name: str) -> bool:
        """Whether a Solid of the top-level node being walked is named ``name`` (true when not searched)."""
        if self.top_walked is None:
            return True
        if not self.top_names_read:
            self.top_solid_names, self.top_names_read = _solid_names(self.top_walked), True
        return self.top_solid_names is None or name in self.top_solid_names

    def slotted(self, end: Node | None) -> Node | None:
        """A joint's end point, through the Slots that hold it (a Slot adds no frame)."""
        while end is not None and end.type == "Slot":
            end = self.fields(end).node_("endPoint")
        return end

    def hinge2_frames(self, node: Node, frame: Frame, first: list[dict], second: list[dict]) -> list[dict]:
        """A Hinge2Joint's two axes (``jointParameters``: axis, default x, anchor and position;
        ``jointParameters2``: axis2, default z, position2) as two hinges through its anchor, the
        second riding on the first (WbHinge2Joint turns its end point by ``R(axis, q1) R(axis2, q2)``
        about the anchor): see :meth:`axis_chain`."""
        f = self.fields(node)
        p1, p2 = f.node_("jointParameters"), f.node_("jointParameters2")
        f1 = self.fields(p1) if p1 is not None else None
        f2 = self.fields(p2) if p2 is not None else None
        axes = [f1.vec("axis", (1.0, 0.0, 0.0)) if f1 else (1.0, 0.0, 0.0),
                f2.vec("axis", (0.0, 0.0, 1.0)) if f2 else (0.0, 0.0, 1.0)]
        positions = [f1.num("position", 0.0) if f1 else 0.0, f2.num("position", 0.0) if f2 else 0.0]
        anchor = f1.vec("anchor", (0.0, 0.0, 0.0)) if f1 else (0.0, 0.0, 0.0)
        return self.axis_chain(frame, anchor, axes, positions, [first, second])

    def ball_frames(self, node: Node, frame: Frame, first: list[dict], second: list[dict],
                    third: list[dict]) -> list[dict]:
        """A BallJoint's three axes as three hinges through its anchor (``jointParameters``, a
        BallJointParameters: anchor and the first position), each riding on the one before
        (WbBallJoint turns its end point by ``R(a1, q1) R(a2, q2) R(a3, q3)`` about the anchor). WbBallJoint's
        axes: a1 is ``jointParameters2``'s axis, a3 ``jointParameters3``'s, a2 = a3 × a1; one of them
        missing, it is the other's cross product with z or x (x or z when that one lies along it);
        both missing, x and z. The second axis's motor is limited to [-pi/2, pi/2] (checkMotorLimit)."""
        f = self.fields(node)
        fs = [self.fields(p) if p is not None else None
              for p in (f.node_("jointParameters"), f.node_("jointParameters2"), f.node_("jointParameters3"))]
        x, z = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
        given2 = np.asarray(fs[1].vec("axis", (0.0, 0.0, 1.0)), dtype=np.float64) if fs[1] else None
        given3 = np.asarray(fs[2].vec("axis", (0.0, 0.0, 1.0)), dtype=np.float64) if fs[2] else None

        def crossed(a: np.ndarray, first_: np.ndarray, other: np.ndarray) -> np.ndarray:
            c = np.cross(a, first_)
            return np.cross(a, other) if not np.any(c) else c

        a1 = given2 if given2 is not None else (x if given3 is None else crossed(given3, z, x))
        a3 = given3 if given3 is not None else (z if given2 is None else crossed(given2, x, z))
        a2 = np.cross(a3, a1)
        positions = [fp.num("position", 0.0) if fp else 0.0 for fp in fs]
        anchor = fs[0].vec("anchor", (0.0, 0.0, 0.0)) if fs[0] else (0.0, 0.0, 0.0)
        for e in second:      # WbBallJoint::checkMotorLimit (never narrower than the joint's position)
            lo, hi = e.get("min_position", 0.0), e.get("max_position", 0.0)
            q = e.get("position", 0.0)
            if lo == hi == 0.0:
                lo, hi = -math.pi / 2, math.pi / 2
            elif lo < -math.pi / 2 or hi > math.pi / 2:
                self.warn(node, f"BallJoint motor {e['name']!r}: the second axis's motor is limited to "
                                "[-pi/2, pi/2] (as Webots limits it)")
                lo, hi = max(lo, -math.pi / 2), min(hi, math.pi / 2)
            e["min_position"], e["max_position"] = min(lo, q), max(hi, q)
        return self.axis_chain(frame, anchor, [tuple(a) for a in (a1, a2, a3)], positions, [first, second, third])

    @staticmethod
    def axis_chain(frame: Frame, anchor: Any, axes: list[Any], positions: list[float],
                   motors: list[list[dict]]) -> list[dict]:
        """Several rotation axes through one anchor, in the joint's parent frame with every position
        at 0, turning the end point by ``R(a1, q1) R(a2, q2) ...`` (Webots' Hinge2Joint and
        BallJoint): as hinges each riding on the one before, every axis is written as it is with the
        axes before it at their initial positions (``R(a1, q1₀) a2``, ...), in the robot's frame,
        on its motor's entry (``motors``: one list per axis, empty without a motor), with the
        anchor; a motor rides on the nearest motorised axis before its own. The motors that move
        the end point, outermost first."""
        turned = np.eye(3)
        at = [float(v) for v in frame.apply(anchor)]
        out: list[dict] = []
        for axis, q0, entries in zip(axes, positions, motors):
            a = np.asarray(axis, dtype=np.float64)
            for e in entries:
                e["axis"] = [float(v) for v in frame.rotation @ (turned @ a)]
                e["anchor"] = list(at)
                if out:
                    e["_on_joint"] = out[-1]
                out.append(e)
            if q0:
                turned = turned @ axis_angle_matrix(a, q0)
        return out

    def hinge2(self, node: Node, frame: Frame, owner: Owner, motors: list[Node], sensors: list[dict],
               spin_sensors: list[dict]) -> None:
        """A Hinge2Joint of a robot: its first axis (``jointParameters``, ``device``) steers, its
        second (``jointParameters2``, ``device2``) turns the wheel, its end point. Both become
        entries of the robot's motorised hinges (the drive mapping judges them)."""
        f = self.fields(node)
        end = f.node_("endPoint")
        spin_motors = [d for d in f.nodes("device2") if d.type in MOTORS]
        centre_at = (0.0, 0.0, 0.0)
        wheel = self.slotted(end)
        if wheel is not None and wheel.type == "Solid":
            centre_at = self.fields(wheel).vec("translation", (0.0, 0.0, 0.0))
        centre = np.asarray(frame.apply(centre_at))
        for params_field, axis_default, found, found_sensors, steers in (
                ("jointParameters", (1.0, 0.0, 0.0), motors, sensors, True),
                ("jointParameters2", (0.0, 0.0, 1.0), spin_motors, spin_sensors, False)):
            params = f.node_(params_field)
            if params is not None:
                self.typos(params)
            pf = self.fields(params) if params is not None else None
            axis = pf.vec("axis", axis_default) if pf else axis_default
            anchor = pf.vec("anchor", (0.0, 0.0, 0.0)) if pf and params_field == "jointParameters" else None
            if not found:
                if found_sensors:       # joint_devices gave it the axis's position: it reads that, still
                    still = float(found_sensors[0].get("position", 0.0))
                    what = "a free wheel, which Webots' physics rolls" if not steers else "a free steering axis"
                    line = (f"PositionSensor on a Hinge2Joint axis without a motor ({params_field}, {what}): listed, "
                            f"reads the axis's position in the world file ({still:g}) and keeps it (nothing turns "
                            "it here)")
                    if steers or not motors:
                        self.warn(node, line)
                    else:               # a car's free front wheel rolls (said after the drive if it is none)
                        owner.free.append({"node": node, "sensors": found_sensors, "line": line,
                                           "steer": self.fields(motors[0]).string("name", "rotational motor"),
                                           "axis": frame.rotation @ np.asarray(axis), "centre": centre, "end": end,
                                           "frame": frame})
                elif not steers and motors:     # a free front wheel without an encoder: it still holds the car up
                    owner.free.append({"node": node, "sensors": [], "line": None,
                                       "steer": self.fields(motors[0]).string("name", "rotational motor"),
                                       "axis": frame.rotation @ np.asarray(axis), "centre": centre, "end": end,
                                       "frame": frame})
                continue
            m = self.fields(found[0])
            turn = frame.rotation @ np.asarray(axis)
            owner.wheels.append({"node": node, "motor": m.string("name", "rotational motor"), "steers": steers,
                                 "max_velocity": m.num("maxVelocity", 10.0), "limits": _limits(m), "axis": turn,
                                 "anchor": np.asarray(frame.apply(anchor)) if anchor is not None else centre,
                                 "centre": centre, "end": end, "frame": frame, "sensors": found_sensors})

    def _steering_groups(self, wheels: list[dict], up: Up) -> list[tuple[dict | None, list[dict]]] | None:
        """A base on more than two steering joints, each carrying driven wheels of its own (a PR2's four
        casters, a rover's steered corners), or on two that are no car's front axle, one behind the
        other (a Shrimp's steered front and back wheels): each steering joint with the driven wheels it
        turns, then (None, the driven wheels riding none); else None (a car steers two on one axle)."""
        steering = [w for w in wheels if w["steers"]]
        held = [self._inside(w["end"]) for w in steering]
        riding = [[w for w in wheels if not w["steers"] and id(w["node"]) in h] for h in held]
        if len(steering) < 2 or not all(riding) or (len(steering) == 2 and self._one_axle(steering, wheels, up)):
            return None
        carried = {id(w["node"]) for r in riding for w in r}
        free = [w for w in wheels if not w["steers"] and id(w["node"]) not in carried]
        return [*zip(steering, riding), *([(None, free)] if free else [])]

    def _tricycle(self, wheels: list[dict], up: Up) -> list[tuple[dict | None, list[dict]]] | None:
        """A tricycle's (a forklift's) steering groups: one steering joint holding a wheel that no motor
        drives the robot with (a passive hinge's wheel, or its end point's round part) and two driven
        wheels or more riding no steering joint, on one axle (coaxial, in the ground's plane), the
        steered wheel ahead of it or behind it. [(None, the driven wheels), (the steering joint, [the
        free wheel, marked "free"])]; else None (a car steers two; a BB-8's driven ball rides its only
        steering joint: :meth:`_one_steered_wheel`)."""
        from sensorium.server.world.wbt.drive import AXIS_TOL, TOL, held_wheel, holds_wheel

        steering = [w for w in wheels if w["steers"]]
        if len(steering) != 1 or steering[0]["node"].type != "HingeJoint" or not holds_wheel(steering[0]["end"], self):
            return None                           # a Hinge2Joint's wheel is a car's (ackermann_drive says why not)
        turn = np.asarray(steering[0]["axis"], dtype=np.float64)
        if float(np.linalg.norm(np.delete(turn, up))) > AXIS_TOL * float(np.linalg.norm(turn)):
            return None                           # no vertical steering axis
        carried = self._inside(steering[0]["end"])
        riding = [w for w in wheels if not w["steers"] and id(w["node"]) in carried]
        driven = [w for w in wheels if not w["steers"] and id(w["node"]) not in carried]
        if len(driven) < 2 or len(riding) > 1:
            return None
        flat = [i for i in range(3) if i != up]
        axis = np.asarray(driven[0]["axis"], dtype=np.float64)[flat]
        if float(np.linalg.norm(axis)) <= TOL:
            return None
        axis /= np.linalg.norm(axis)
        base = np.asarray(driven[0]["anchor"], dtype=np.float64)[flat]
        for w in driven[1:]:
            other = np.asarray(w["axis"], dtype=np.float64)[flat]
            off = np.asarray(w["anchor"], dtype=np.float64)[flat] - base
            if abs(float(other[0] * axis[1] - other[1] * axis[0])) > TOL * float(np.linalg.norm(other)) or \
                    abs(float(off[0] * axis[1] - off[1] * axis[0])) > TOL:
                return None                       # not on one axle
        ahead = np.asarray(steering[0]["anchor"], dtype=np.float64)[flat] - base
        if abs(float(ahead[0] * axis[1] - ahead[1] * axis[0])) <= TOL:
            return None                           # the steered wheel on the axle's line: no wheelbase
        if riding:
            free = {**riding[0], "free": True}
        else:                                     # a passive hinge or the end point's round part: it rolls along
            end = held_wheel(steering[0]["end"], self)      # forward at steering position 0
            if end is None:
                return None
            free = {"end": end, "axis": None, "free": True}
        return [(None, driven), (steering[0], [free])]

    def _steered(self, node: Node, robot: Owner, groups: list, driven: list[dict], up: Up) -> bool:
        """The steered-wheel drive of ``groups`` (steering joint, the wheels it turns) made the robot's, its
        ``driven`` wheels the drive's (the steering hinges stay joints, moved as Webots' kinematic motor
        control moves them; the drive reads their positions); False, with one line, when there is none."""
        from sensorium.server.world.wbt.drive import steered_drive

        positions = {d["name"]: float(d.get("position", 0.0)) for d in robot.data["devices"]
                     if d.get("device") == "RotationalMotor"}
        drive, why = steered_drive(groups, positions, self, up)
        if drive is None:
            self.warn(node, f"robot {robot.data['name']!r}: no steered-wheel drive ({why}); the robot will not move")
            return False
        robot.data["steered_drive"] = drive
        self._drive_wheels(node, robot, driven)
        return True

    def _one_axle(self, steering: list[dict], wheels: list[dict], up: Up) -> bool:
        """Whether two steering joints stand on one axle, as a car's front wheels do: the line between
        their anchors, in the ground's plane, along the axis of the wheels riding no steering joint (the
        robot's y when every wheel is steered)."""
        from sensorium.server.world.wbt.drive import TOL

        flat = [i for i in range(3) if i != up]
        d = (np.asarray(steering[0]["anchor"], dtype=np.float64) - np.asarray(steering[1]["anchor"], dtype=np.float64))[flat]
        carried: set[int] = set().union(*(self._inside(w["end"]) for w in steering))
        free = [w for w in wheels if not w["steers"] and id(w["node"]) not in carried]
        axis = np.asarray(free[0]["axis"], dtype=np.float64)[flat] if free else np.array([0.0, 1.0])
        if float(np.linalg.norm(axis)) <= TOL or float(np.linalg.norm(d)) <= TOL:
            return True
        return abs(float(d[0] * axis[1] - d[1] * axis[0])) <= TOL * float(np.linalg.norm(d) * np.linalg.norm(axis))

    def _grounded(self, groups: list[tuple[dict | None, list[dict]]], nowheel: list[tuple[Node, str, str, str]],
                  up: Up) -> list[tuple[dict | None, list[dict]]]:
        """The steering groups with the driven hinges riding no steering joint kept only where they are
        wheels on the steered wheels' ground (their round part's bottom within the smallest steered
        wheel's radius of the lowest steered wheel's): a head's tilt hinge or an arm's joint beside
        the casters is no wheel (said once, with the robot's other joints)."""
        from sensorium.server.world.wbt.drive import wheel_bottom, wheel_radius

        steered = [w for steering, riding in groups if steering is not None for w in riding]
        radii = [r for r in (wheel_radius(w["end"], self) for w in steered) if r is not None]
        lowest = wheel_bottom(steered, self, up)
        out: list[tuple[dict | None, list[dict]]] = []
        for steering, riding in groups:
            if steering is not None:
                out.append((steering, riding))
                continue
            kept = []
            for w in riding:
                bottom = wheel_bottom([w], self, up)
                if bottom is not None and lowest is not None and radii and abs(bottom - lowest) <= min(radii):
                    kept.append(w)
                else:
                    nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (no "
                                    f"round part on the ground the steered wheels roll on): {JOINT_MOVES}",
                                    "off the ground the steered wheels roll on"))
            if kept:
                out.append((None, kept))
        return out

    def _suspension(self, wheels: list[dict], up: Up) -> list[tuple[dict, str]]:
        """The hinges of a rocker-bogie (a Sojourner's rockers and bogies), each with the names of the
        wheels it carries: a motorised hinge that steers nothing and whose end point carries one or more
        of the robot's wheels on the ground -- motorised hinges carrying no motorised hinge whose round
        part turns about their axis as a wheel's does (:func:`rolls_about_its_axis`), its bottom within
        the smallest such radius of the lowest, three such wheels at least (a Sojourner's front bogie
        carries its front wheel only). An arm's chain or a leg (its knee's round foot below the knee's
        axis, not on it) carries none of them, so its hinges stay links (no wheels)."""
        from sensorium.server.world.wbt.drive import rolls_about_its_axis, wheel_bottom, wheel_radius

        inside = {id(w["node"]): self._inside(w["end"]) for w in wheels}
        motorised = {id(w["node"]) for w in wheels}
        ends = []
        for w in wheels:
            if w["steers"] or inside[id(w["node"])] & motorised or not rolls_about_its_axis(w, self):
                continue
            radius, bottom = wheel_radius(w["end"], self), wheel_bottom([w], self, up)
            if radius is not None and bottom is not None:
                ends.append((w, bottom, radius))
        if len(ends) < 3:
            return []
        lowest, reach = min(b for _, b, _ in ends), min(r for _, _, r in ends)
        ground = [w for w, b, _ in ends if b - lowest <= reach]
        out = []
        for w in wheels:
            carried = [g["motor"] for g in ground if id(g["node"]) in inside[id(w["node"])]]
            if not w["steers"] and carried:
                out.append((w, ", ".join(repr(m) for m in carried)))
        return out

    def _lifted_wheels(self, wheels: list[dict], up: Up) -> list[tuple[dict, float]]:
        """The motorised hinges about horizontal axes whose round part's bottom is more than the lowest
        wheels' diameter above their bottom, with that height, when at least two wheels are at the
        bottom (a base that stands on them); else none. Such a part never touches the ground the base
        rolls on, whether it rides a pan hinge (a TIAGo++'s head) or, turning about its axis as a wheel
        would, the body itself (a camera ball on a tilt hinge); an arm's link that turns otherwise is
        left to the drive's own reason (nothing round turns about its axis)."""
        from sensorium.server.world.wbt.drive import GROUND_TOL, rolls_about_its_axis, wheel_bottom, wheel_radius

        rolling = []
        for w in wheels:
            radius = None if w["steers"] else wheel_radius(w["end"], self)
            bottom = wheel_bottom([w], self, up) if radius is not None else None
            if radius is not None and bottom is not None:
                rolling.append((w, bottom, radius))
        if len(rolling) < 3:
            return []
        lowest = min(b for _, b, _ in rolling)
        base = [(w, r) for w, b, r in rolling if b - lowest <= GROUND_TOL]
        if len(base) < 2:
            return []
        reach = 2.0 * max(r for _, r in base)
        steered: set[int] = set().union(*(self._inside(w["end"]) for w in wheels if w["steers"]))
        return [(w, b - lowest) for w, b, _ in rolling
                if b - lowest > reach and (id(w["node"]) in steered or rolls_about_its_axis(w, self))]

    def _one_steered_wheel(self, wheels: list[dict]) -> str | None:
        """Why a robot whose only driven wheel rides a steering joint (a BB-8's ball rolled inside
        its body yaw joint, a unicycle's wheel under its fork) has no drive, else None: no car rolls
        on one wheel."""
        driven = [w for w in wheels if not w["steers"]]
        if len(driven) != 1:
            return None
        carriers = [w for w in wheels if w["steers"] and id(driven[0]["node"]) in self._inside(w["end"])]
        if not carriers:
            return None
        return (f"its only driven wheel, {driven[0]['motor']!r}, turns inside the steering joint "
                f"{carriers[0]['motor']!r}: a robot on one wheel (a ball its weight rolls, a unicycle) moves by "
                "Webots' physics, and no kinematic drive here rolls on one wheel")

    def _inside(self, end: Node | None) -> set[int]:
        """The ids of every node inside the end point ``end`` (its children, its joints' end points
        and devices, to any depth)."""
        out: set[int] = set()
        stack = [end] if end is not None else []
        while stack:
            n = stack.pop()
            self.walk(n)
            for key in ("children", "device", "device2", "device3", "endPoint"):
                held = n.fields.get(key)      # the raw value: a field of another meaning is no node
                for c in held if isinstance(held, list) else [held]:
                    if isinstance(c, Node):
                        out.add(id(c))
                        stack.append(c)
        return out

    def drive(self, node: Node, robot: Owner) -> None:
        """The robot's drive from its motorised hinges; every motor found to be no wheel is said once
        (one line each, or one line for the robot when it has more than MANY_JOINTS of them: a
        humanoid's, a legged robot's or an arm's joints)."""
        nowheel: list[tuple[Node, str, str, str]] = []      # (joint node, motor, its own line, the reason)
        self._track_drive(node, robot)
        try:
            self._drive(node, robot, nowheel)
        finally:
            self._say_no_wheels(node, robot, nowheel)
            self._say_body_stays(node, robot, nowheel)
            from sensorium.server.world.wbt.drive import free_car_wheels

            car = robot.data.get("ackermann_drive")
            up = self._robot_up(robot)
            rolling = free_car_wheels(car, robot.free, self, up)
            for free in robot.free:     # an encoder on a wheel axis no motor turns and no car rolls: still
                if id(free) not in rolling and free["line"] is not None:
                    self.warn(free["node"], free["line"])
            if car is not None and rolling and self.fields(node).node_("physics") is not None \
                    and self._settles_along(up):
                self._free_wheel_bottom(car, [f for f in robot.free if id(f) in rolling], up)
            if car is not None:
                self._car_axles_done(car)

    def track(self, node: Node, frame: Frame, owner: Owner, motor: dict, line: str) -> None:
        """A robot's Track driven by its LinearMotor (``motor``'s entry), kept for ``_track_drive``:
        its belt's direction (the Track's x) and origin in the robot's frame, its TrackWheels, and the
        load report's line for it should it drive nothing."""
        wheels = []
        for child in self.fields(node).nodes("children"):
            if child.type == "TrackWheel":
                cf = self.fields(child)
                x, y = cf.vec("position", (0.0, 0.0))
                wheels.append((x, y, cf.num("radius", 0.1)))
        owner.tracks.append({"node": node, "entry": motor, "motor": motor["name"], "line": line,
                             "max_velocity": float(motor.get("max_velocity", 10.0)),
                             "forward": np.asarray(frame.rotation, dtype=np.float64)[:, 0],
                             "origin": np.asarray(frame.apply((0.0, 0.0, 0.0))),
                             "frame": frame, "wheels": wheels})

    def bounds_bottom(self, node: Node, frame: Frame, up: Up = UP_Z) -> float | None:
        """The lowest point along the robot's axis ``up`` of ``node``'s boundingObject (its Boxes,
        Cylinders, Capsules and Spheres, under Group, Pose and Transform nodes and Shapes), ``frame``
        the node's frame in the robot's; None when it holds none of these. Webots' physics rests a Track
        on its bounding object (its TrackWheels have none), which may reach below the wheels' circles. A
        Cylinder's and a Capsule's axis is their z, as in Webots since R2022a (:func:`geometry.reach`)."""
        low: list[float] = []
        for g_node, place in self._bounding_geometries(node, frame):
            prim = self._bounding_primitive(g_node, place.scale) if place.stretch is None else None
            if prim is not None:
                row = np.asarray(place.rotation, dtype=np.float64)[up, :]   # the robot's up in the shape's frame
                low.append(float(place.apply((0.0, 0.0, 0.0))[up]) - geo.reach(prim, row))
        return min(low) if low else None

    def _bounding_primitive(self, g_node: Node, s: float) -> geo.Box | geo.Sphere | geo.Cylinder | geo.Capsule | None:
        """A Box, Sphere, Cylinder or Capsule bounding node as a primitive, scaled by ``s``, its sizes
        sanitised as Webots' (a non-positive one 1); None for any other node."""
        g = self.fields(g_node)
        if g_node.type == "Box":
            return geo.Box(tuple(v * s for v in g.positive_vec("size", (2.0, 2.0, 2.0), (1.0, 1.0, 1.0))))
        if g_node.type == "Sphere":
            return geo.Sphere(g.positive("radius", 1.0) * s)
        if g_node.type in ("Cylinder", "Capsule"):
            kind = geo.Cylinder if g_node.type == "Cylinder" else geo.Capsule
            return kind(g.positive("radius", 1.0) * s, g.positive("height", 2.0) * s)
        return None

    def _bounding_geometries(self, node: Node, frame: Frame) -> list[tuple[Node, Frame]]:
        """The geometry nodes of ``node``'s boundingObject, each with its frame (``frame`` the node's): the
        geometry itself, a Shape's, or those under Group, Pose and Transform nodes of any depth."""
        out: list[tuple[Node, Frame]] = []

        def visit(bo: Node | None, place: Frame) -> None:
            if bo is None:
                return
            if bo.type in ("Group", "Pose", "Transform"):
                inner = place if bo.type == "Group" else self.child_frame(bo, place)
                for child in self.fields(bo).nodes("children"):
                    visit(child, inner)
                return
            if bo.type == "Shape":
                bo = self.fields(bo).node_("geometry")
            if bo is not None:
                out.append((bo, place))

        visit(self.fields(node).node_("boundingObject"), frame)
        return out

    def belts(self, node: Node, frame: Frame, motor: str, up: Up = UP_Z) -> list[dict]:
        """A Track's belt as a conveyor carries on it (schemas ConveyorBelt): the top face of each Box in
        its boundingObject (the Box itself, a Shape of one, or under Group, Pose and Transform nodes of any
        number of children: an offset or a turn; a tilt the simulation finds not level), in the robot's
        frame, each moving along the Track's own +x as Webots moves every contact of a Track's bounding
        object; no face when it holds no Box (its other geometries carry nothing here). The face's normal
        is the Box's axis ``up`` (the robot's: z, or y for a robot built y-up in a NUE world)."""
        forward = np.asarray(frame.rotation, dtype=np.float64)[:, 0]
        return [self._belt_face(box, place, forward, motor, up) for box, place in self._bounding_geometries(node, frame)
                if box.type == "Box" and place.stretch is None]

    def _belt_face(self, box: Node, place: Frame, forward: np.ndarray, motor: str, up: Up) -> dict:
        """One Box's top face placed at ``place``: its sides named so that ``along`` is the one nearest the
        Track's +x (``forward``), and ``direction``, the Track's +x, given when it is not ``along`` exactly
        (a Box turned in a Pose about the Track's up)."""
        size = [float(v) for v in self.fields(box).vec("size", (2.0, 2.0, 2.0))]
        r = np.asarray(place.rotation, dtype=np.float64)
        # the face's two sides, right-handed about its normal (x, y about z; x, -z about y)
        side = r[:, 1] if up == 2 else -r[:, 2]
        length, width = size[0], size[1] if up == 2 else size[2]
        top = [0.0, 0.0, 0.0]
        top[up] = size[up] / 2.0
        along, across = r[:, 0], side
        if abs(side @ forward) > abs(along @ forward):     # a Box turned a quarter: its other side runs along
            along, across, length, width = side, -r[:, 0], width, length
        if along @ forward < 0.0:
            along, across = -along, -across
        face = {"motor": motor, "top": tuple(float(v) for v in place.apply(tuple(top))),
                "along": tuple(float(v) for v in along), "across": tuple(float(v) for v in across),
                "length": length * place.scale, "width": width * place.scale}
        if not np.array_equal(along, forward):
            face["direction"] = tuple(float(v) for v in forward)
        return face

    def _track_drive(self, node: Node, robot: Owner) -> None:
        """A robot with two motorised Tracks and no motorised hinge that is a wheel drives on them: their
        motors are its ``differential_drive``'s wheels of radius 1 (wbt/drive.py ``track_drive``), their
        entries kept LinearMotors (controllers see Webots' types); otherwise each Track is said once (a
        conveyor belt's one). Hinges whose end points have nothing round to roll on (Webots' TrackedRobot's
        camera head) move as joints beside the belts, as Webots' physics drives the belts whatever else moves."""
        from sensorium.server.world.wbt.drive import belt_bottom, track_drive, wheel_radius

        tracks = robot.tracks
        if not tracks:
            return
        up = self._robot_up(robot, on_side=False)
        rolls = any(wheel_radius(w["end"], self) is not None for w in robot.wheels)
        drive, why = (None, "") if rolls or len(tracks) != 2 else track_drive(tracks, self, up)
        if drive is not None and self.in_rider:       # fixed in its carrier's frame: its belts carry, it rolls nowhere
            drive, why = None, f"it rides robot {self.in_rider!r}, fixed in its frame"
        if drive is None:
            if why:
                self.warn(node, f"robot {robot.data['name']!r}: no tracked drive ({why}); the robot will not move")
            for t in tracks:
                faces = self.belts(t["node"], t["frame"], t["motor"], up)
                if not faces:
                    self.warn(t["node"], t["line"])
                    continue
                robot.data.setdefault("belts", []).extend(faces)   # a conveyor (sim/belt.py)
                self.warn(t["node"], f"Track {self.fields(t['node']).string('name', 'solid')!r}: its belt carries "
                          "the solids with physics lying on its top face at its motor's velocity; its texture "
                          "animation and wheels do not move here")
            return
        bottoms = [self.bounds_bottom(t["node"], t["frame"], up) for t in tracks]   # what Webots' physics rests on
        bottoms = [b if b is not None else belt_bottom(t["frame"], t["wheels"], up) for b, t in zip(bottoms, tracks)]
        if self.fields(node).node_("physics") is not None and all(b is not None for b in bottoms):
            drive["wheel_bottom"] = min(b for b in bottoms if b is not None)
        robot.data["differential_drive"] = drive
        for t in tracks:    # the drive's wheel now, still a LinearMotor (Webots' getType); its speed is the drive's
            entry = t["entry"]
            for key in (*JOINT_KEYS, "max_force"):
                entry.pop(key, None)
            entry["_wheel"] = True

    def _free_wheel_bottom(self, car: dict, free: list[dict], up: Up) -> None:
        """A car's free wheels (no motor: a propulsion car's front ones, a traction car's rear ones) hold
        it up as its driven ones do: its ``wheel_bottom`` is the lowest of them all, each with its radius
        (along the robot's ``up``, :meth:`_robot_up`)."""
        from sensorium.server.world.wbt.drive import wheel_bottom

        bottom = wheel_bottom(free, self, up)
        if bottom is not None:
            car["wheel_bottom"] = min(car.get("wheel_bottom", bottom), bottom)
            self._car_axles(car, free, up)

    def _car_axles(self, car: dict, wheels: list[dict], up: Up) -> None:
        """A car's ``axle_bottoms`` (rear, front) from its driven and free wheels, kept when both axles'
        are known and differ by more than GROUND_TOL: wheels of two sizes (Webots' Tractor), so Webots'
        physics leans it until both axles touch the ground."""
        from sensorium.server.world.wbt.drive import axle_bottoms

        known = dict(zip(("rear", "front"), car.pop("axle_bottoms", None) or (None, None)))
        for axle, bottom in axle_bottoms(car, wheels, self, up).items():
            was = known.get(axle)
            known[axle] = bottom if was is None else min(was, bottom)
        car["axle_bottoms"] = (known.get("rear"), known.get("front"))   # the free wheels may give the other

    @staticmethod
    def _car_axles_done(car: dict) -> None:
        """Keep a car's ``axle_bottoms`` only when both axles' are known and differ by more than GROUND_TOL."""
        from sensorium.server.world.wbt.drive import GROUND_TOL

        rear, front = car.pop("axle_bottoms", None) or (None, None)
        if rear is not None and front is not None and abs(rear - front) > GROUND_TOL:
            car["axle_bottoms"] = (rear, front)

    def _robot_up(self, robot: Owner, on_side: bool = True) -> Up:
        """The robot's own axis that stands up, its wheels judged with it for their z (wbt/drive.py): the
        axis closest to the world's up when it is that within ROBOT_UPRIGHT_TOL (a robot built on its side:
        Tinkerbots' base turned -pi/2 about y, its x up), else its z, or in a NUE world its y when that is
        nearer the world's up (a robot built y-up, as Webots' were before R2022a; ``on_side`` False: these
        two only, as Tracks and belts are judged). Its ``wheel_bottom`` is measured along its z or a NUE
        robot's y (:meth:`_settles_along`)."""
        from sensorium.server.world.poses import ROBOT_UPRIGHT_TOL, pose_from_model

        r = pose_from_model(wm.Pose.model_validate(robot.data["pose"])).rotation
        world_up = 1 if self.world["world_info"].get("coordinate_system", "ENU") == "NUE" else 2
        nearest = int(np.argmax(np.abs(r[world_up])))
        if on_side and abs(r[world_up, nearest]) >= 1.0 - 0.5 * ROBOT_UPRIGHT_TOL ** 2:   # within ROBOT_UPRIGHT_TOL rad
            # (its negative end up: built on its side the other way, or upside down, its wheels' rolling turned)
            return Up(nearest, 1.0 if r[world_up, nearest] > 0.0 else -1.0)
        if world_up == 2:
            return UP_Z
        return Up(1) if abs(r[1, 1]) > abs(r[1, 2]) else UP_Z

    def _settles_along(self, up: Up) -> bool:
        """Whether a robot whose own ``up`` axis stands up settles on the ground at load (sim/ground.py's
        ``robot_up``: its z, or a NUE world's robot's y); one built on another side keeps its height."""
        nue = self.world["world_info"].get("coordinate_system", "ENU") == "NUE"
        return up.sign > 0.0 and (up == 2 or (nue and up == 1))

    def _say_no_wheels(self, node: Node, robot: Owner, nowheel: list[tuple[Node, str, str, str]]) -> None:
        if len(nowheel) <= MANY_JOINTS:
            for joint, _motor, line, _why in nowheel:
                end = self.fields(joint).node_("endPoint")
                if end is not None and end.type == "SolidReference" and line.endswith(JOINT_MOVES):
                    name = self.fields(end).string("solidName", "")
                    nothing = JOINT_MOVES_NOTHING if self.names_a_solid(name) else JOINT_MOVES_NO_SOLID
                    line = line[:-len(JOINT_MOVES)] + nothing.format(name=name)
                self.warn(joint, line)
            return
        reasons: dict[str, int] = {}
        for _joint, _motor, _line, why in nowheel:
            reasons[why] = reasons.get(why, 0) + 1
        why = "; ".join(f"{n} {r}" for r, n in reasons.items())
        names = [motor for _joint, motor, _line, _why in nowheel]
        shown = ", ".join(repr(n) for n in names[:MANY_JOINTS])
        self.warn(node, f"robot {robot.data['name']!r}: its {len(names)} motorised joints are no wheels ({why}): "
                        f"they move kinematically (Webots' rule without physics; their PositionSensors read them), "
                        f"and the shapes and devices past each joint with it ({shown} and "
                        f"{len(names) - MANY_JOINTS} more)")

    def _say_body_stays(self, node: Node, robot: Owner, nowheel: list[tuple[Node, str, str, str]]) -> None:
        """A robot with physics, no drive and many motorised joints (a legged robot, a humanoid: Webots'
        Spot, Nao): Webots' physics stands, walks or drops it by its limbs; here its joints move only
        its parts. One line, so a controller's walk going nowhere is not a surprise."""
        drives = ("differential_drive", "ackermann_drive", "mecanum_drive", "omni_drive", "steered_drive")
        if (len(nowheel) <= MANY_JOINTS or any(k in robot.data for k in drives)
                or self.fields(node).node_("physics") is None):
            return
        self.warn(node, f"robot {robot.data['name']!r}: its joints move its parts, never its body: without "
                        "physics nothing here stands it on its limbs, walks, sits or drops it (its body stays "
                        "where the world file or a Supervisor puts it)")

    def _drive(self, node: Node, robot: Owner, nowheel: list[tuple[Node, str, str, str]]) -> None:
        from sensorium.server.world.wbt.drive import (
            AXIS_TOL,
            ackermann_drive,
            car_engine,
            differential_drive,
            has_rollers,
            holds_wheel,
            mecanum_drive,
            mecanum_turns,
            omni_drive,
            omni_wheels,
            one_motor_axle,
            rolls_about_its_axis,
            spins_in_place,
            webots_kinematic_pair,
            wheel_radius,
        )

        wheels = robot.wheels
        if not wheels:
            return
        if self.in_rider:               # fixed in its carrier's frame (Webots: no joint between them), it rolls nowhere
            for w in wheels:
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (robot "
                                f"{robot.data['name']!r} rides robot {self.in_rider!r}, fixed in its frame): {JOINT_MOVES}",
                                "its robot rides another"))
            return
        up = self._robot_up(robot)      # the robot's own up axis: its z, a y-up robot's y in a NUE world
        if up != 2:                     # a y-up robot's hinge steers about its y (the walk judged its z)
            for w in wheels:
                if w["node"].type == "HingeJoint":
                    w["steers"] = abs(float(w["axis"][up])) > 0.9 * float(np.linalg.norm(w["axis"]))
        round_ = [wheel_radius(w["end"], self) is not None for w in wheels]
        rounded = {id(w): r for w, r in zip(wheels, round_)}       # read once: the fallback below asks again
        if len(wheels) == 1 and wheels[0]["node"].type == "HingeJoint" and round_[0] \
                and self.fields(node).node_("physics") is not None:
            # one motorised hinge carrying the wheels of both sides (Tinkerbots' vision_car): Webots' physics
            # rolls the robot straight on them; a turntable's or a lone wheel's hinge is none (wbt/drive.py)
            drive, why = one_motor_axle(wheels[0], robot.free, self, up)
            if drive is not None:
                robot.data["steered_drive"] = drive
                self._drive_wheels(node, robot, wheels)
                return
        if len({id(w["node"]) for w in wheels}) == 1 or not any(round_):
            # one motorised hinge (Webots' motor sample: a turntable; motor2's one Hinge2Joint, its
            # two axes the joint's), or nothing round to roll on at
            # any (an arm, a gripper's fingers, a pan-tilt head): no vehicle, so no drive to miss;
            # each joint moves kinematically
            for w, rolls in zip(wheels, round_):
                only = "hinge" if w["node"].type == "HingeJoint" else "joint"
                why = f"the robot's only motorised {only}" if rolls else "its end point has no cylinder or sphere to roll on"
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel ({why}): "
                                                       f"{JOINT_MOVES}", "with no cylinder or sphere at their end point to roll on"
                                if not rolls else "the robot's only motorised joint"))
            return
        # a steered "wheel" high above the robot's lowest ones (a head's tilt hinge whose end point is
        # a sphere, riding the pan hinge as a car's wheel rides its steering) never touches the ground
        # they roll on: no wheel, and a steering joint left holding none of them steers none
        lifted = self._lifted_wheels(wheels, up)
        if lifted:
            for w, height in lifted:
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (its round "
                                f"part's bottom is {height:.3g} m above the robot's lowest wheels: it never touches "
                                f"the ground): {JOINT_MOVES}", "high above the ground the wheels roll on"))
            wheels = [w for w in wheels if not any(w is l for l, _ in lifted)]
        # a vertical hinge whose end point neither is nor carries a wheel (a pan head, an arm's base
        # joint on a mobile robot) steers nothing: it is no wheel, and the others make the drive (with
        # vertical hinges only, there is no vehicle: said below)
        # so is one that spins its round part in place about its own axis (a lidar's spinning head)
        gone = {id(w["node"]) for w, _ in lifted}
        holding = {id(w["node"]) for w in wheels if w["steers"] and holds_wheel(w["end"], self)}
        spinning = {id(w["node"]) for w in wheels if id(w["node"]) in holding and w["node"].type == "HingeJoint"
                    and spins_in_place(w, self)}
        # (with parts lifted, one that carries no wheel left: a TIAGo++'s head pan; but not a car's steering
        # joint whose end point is its free wheel on the ground, below the lowest axle)
        ground = min((float(w["centre"][up]) * up.sign for w in wheels if rounded[id(w)]), default=0.0)

        def on_ground(w: dict) -> bool:
            radius = wheel_radius(w["end"], self)
            return radius is not None and float(w["centre"][up]) * up.sign - radius <= ground

        pans = [w for w in wheels if w["steers"] and (id(w["node"]) not in holding or id(w["node"]) in spinning or (
            gone and not on_ground(w) and not any(id(o["node"]) in self._inside(w["end"])
                                                  for o in wheels if not o["steers"])))]
        if pans and not all(w["steers"] for w in wheels):
            for w in pans:
                why = ("it spins its round part in place about its own axis" if id(w["node"]) in spinning
                       else "its end point holds no wheel")
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel and steers "
                                f"none ({why}): {JOINT_MOVES}", "steering none"))
            wheels = [w for w in wheels if not any(w is p for p in pans)]
        # a rocker-bogie's suspension (a Sojourner's rockers and bogies): motorised hinges carrying the
        # wheels; they are no wheels, and the wheels riding them are wheels still
        suspension = self._suspension(wheels, up)
        if suspension:
            for w, carried in suspension:
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (a "
                                f"rocker-bogie's suspension hinge: its end point carries the wheels {carried}): "
                                f"{JOINT_MOVES}", "suspension hinges of a rocker-bogie"))
            wheels = [w for w in wheels if not any(w is s for s, _ in suspension)]
        # an arm's chain (a vacuum gripper's pitch and roll hinges): a wheel carries no motorised
        # hinge and rides on none but its steering joint, so a hinge that does either is no wheel
        inside = {id(w["node"]): self._inside(w["end"]) for w in wheels if not w["steers"]}
        links = [w for w in wheels if not w["steers"] and
                 (any(id(o["node"]) in inside[id(w["node"])] for o in wheels) or
                  any(id(w["node"]) in held for held in inside.values()))]
        if links:
            for w in links:
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (a link "
                                f"of a chain of motorised joints, carrying one or carried by one): {JOINT_MOVES}",
                                "links of a chain of motorised joints"))
            wheels = [w for w in wheels if not any(w is k for k in links)]
            if len(wheels) == 1 and not wheels[0]["steers"]:
                w = wheels[0]
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (the "
                                f"robot's only other motorised hinge): {JOINT_MOVES}", "the only other motorised hinge"))
                return
            if not wheels:
                return
        if wheels and all(w["steers"] for w in wheels):
            # vertical hinges only, none driving a wheel (a gripper's fingers whose end points hold
            # their axles, coaxial cylinders that roll on nothing): no vehicle, no drive to miss
            for w in wheels:
                nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (it turns "
                                f"about a vertical axis and no motor of the robot drives a wheel): {JOINT_MOVES}",
                                "turning about a vertical axis"))
            return
        sideways = up == 0 or up.sign < 0.0      # on its side (x up), or its -x, -y or -z up
        if sideways and any(w["steers"] for w in wheels):
            # a robot built on its side (its x up: Tinkerbots' base) or with an axis's negative end up is judged
            # for a two-wheel, skid-steer or one-motor drive only (the other drives' frames take a z or y up)
            steering = next(w["motor"] for w in wheels if w["steers"])
            axis = ("-" if up.sign < 0.0 else "") + "xyz"[up]
            how = "upside down" if axis == "-z" else "built on its side"
            self.warn(node, f"robot {robot.data['name']!r}: no drive (it is {how}, its {axis} up, where only "
                            f"wheels about one horizontal axis make a drive here; motor {steering!r} turns about its "
                            f"{axis[-1]}); the robot will not move")
            return
        if not sideways and omni_wheels(wheels, self, up):     # three or more wheels about horizontal axes not along one line
            drive, why = omni_drive(wheels, self, up)
            if drive is None:
                self.warn(node, f"robot {robot.data['name']!r}: no omni drive ({why}); the robot will not move")
                return
            plain = [w["motor"] for w in wheels if not has_rollers(w, self)]
            if plain:
                self.warn(node, f"robot {robot.data['name']!r}: wheel(s) {', '.join(repr(m) for m in plain)} show no "
                                "rollers (passive hinges across their axis) nor asymmetric friction: taken as omni "
                                "wheels, which slip freely along their axes (Webots' physics makes plain wheels "
                                "grip there, so such a robot moves only where no wheel would slide sideways)")
            robot.data["omni_drive"] = drive
            self._drive_wheels(node, robot, wheels)
            return
        turns = None                              # mecanum rollers: the wheels' friction turned (wbt/drive.py)
        if any(w["steers"] for w in wheels):
            # a mecanum base carrying an arm whose first joint turns about the vertical (a youBot): the
            # arm's joints are no wheels (no car steers mecanum wheels), the base's wheels make the drive
            carried: set[int] = set().union(*(self._inside(w["end"]) for w in wheels if w["steers"]))
            base = [w for w in wheels if not w["steers"] and id(w["node"]) not in carried]
            turns = mecanum_turns(base, self) if base else None
            if turns is not None:
                for w in wheels:
                    if not any(w is b for b in base):
                        nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel "
                                        f"(an arm's joint on a mecanum base): {JOINT_MOVES}", "an arm's joints"))
                wheels = base
        elif not sideways:
            turns = mecanum_turns(wheels, self)
        groups = self._steering_groups(wheels, up) if turns is None else None
        if groups is not None:                    # steered casters or corners: each wheel steered on its own
            groups = self._grounded(groups, nowheel, up)
            self._steered(node, robot, groups, [w for _, riding in groups for w in riding], up)
            return
        tricycle = self._tricycle(wheels, up) if turns is None else None
        if tricycle is not None:                  # two driven wheels and a steered free one (Webots' sick sample)
            # a motorised hinge of the free wheel stays a joint too (its motor, never commanded by a
            # tricycle's controller, moves that joint, not the drive)
            if not self._steered(node, robot, tricycle, tricycle[0][1], up):
                return
            # an encoder on the free wheel's passive hinge reads what the wheel rolls (positive: rolling forward
            # turns the hinge about its axis, the robot's left at steering 0)
            held = tricycle[1][1][0]["end"]
            for free in robot.free:
                if free["end"] is held and free["sensors"]:
                    left = np.array([0.0, 1.0, 0.0]) if up == 2 else np.array([0.0, 0.0, -1.0])
                    for sensor in free["sensors"]:
                        sensor["free_wheel"] = len(tricycle[0][1])
                        if float(np.dot(free["axis"], left)) < 0.0:
                            sensor["free_wheel_sign"] = -1
                    free["line"] = None
            return
        if turns is None and any(w["steers"] for w in wheels):      # a car
            casters = self._one_steered_wheel(wheels)
            if casters:
                self.warn(node, f"robot {robot.data['name']!r}: no drive ({casters}); the robot will not move")
                return
            drive, why = ackermann_drive(wheels, self, up)
            # a car's fittings (Webots' BmwX5: its wipers, steering wheel and speedometer needles, on hinges
            # its driver library turns): a motorised hinge about an axis off the horizontal, with nothing
            # round at its end point, or one whose round part's lowest point is above the lowest wheel axle
            # (a mixer's drum, a fan: nothing on the ground), rolls on nothing;
            # the car is the rest when the rest make one
            def height(w: dict) -> float:
                return up.sign * float(w["centre"][up])

            axle = min((height(w) for w in wheels if rounded[id(w)]), default=0.0)
            fittings = [w for w in wheels if not w["steers"] and (
                not rounded[id(w)] or abs(float(w["axis"][up])) > AXIS_TOL * float(np.linalg.norm(w["axis"]))
                or height(w) - float(wheel_radius(w["end"], self) or 0.0) > axle)]
            # and the upright hinges riding a fitting (a mirror's pitch on its yaw) or turning a round part
            # off the ground (a beacon, a radar on the roof): they steer no wheel
            riding = set().union(*(self._inside(f["end"]) for f in fittings))
            fittings += [w for w in wheels if w["steers"] and (
                id(w["node"]) in riding or height(w) - float(wheel_radius(w["end"], self) or 0.0) > axle)]
            if drive is None and fittings:
                rest = [w for w in wheels if not any(w is f for f in fittings)]
                fitted, _ = ackermann_drive(rest, self, up) if any(not w["steers"] for w in rest) else (None, "")
                if fitted is not None:
                    drive = fitted
                    for w in fittings:
                        nowheel.append((w["node"], w["motor"], f"{w['node'].type} motor {w['motor']!r} is no wheel (a "
                                        "car's fitting: its axis is off the horizontal or its end point has nothing "
                                        f"round to roll on the ground): {JOINT_MOVES}", "a car's fittings"))
                    wheels = rest
            if drive is None:
                self.warn(node, f"robot {robot.data['name']!r}: no Ackermann drive ({why}); the robot will not move")
                return
            engine = car_engine(robot.data.get("custom_data", ""))      # a Webots Car's engineType
            if engine is not None and engine != "combustion":
                drive["engine_type"] = engine
            robot.data["ackermann_drive"] = drive
        elif turns is not None:                   # rollers: friction turned on the wheels
            drive, why = mecanum_drive(wheels, turns, self, up)
            if drive is None:
                self.warn(node, f"robot {robot.data['name']!r}: no mecanum drive ({why}); the robot will not move")
                return
            robot.data["mecanum_drive"] = drive
        else:
            drive, why = differential_drive(wheels, self, up)
            # a motorised hinge whose end point has nothing round to roll on (a gripper's lift arm, a
            # flipper) is no wheel, nor, that failing, one whose round part does not turn about its axis
            # (an arm's link of a plain cylinder, across the axis or off it): the drive is the wheels
            # without them, if they make one
            for rolls, reason in ((lambda w: rounded[id(w)],
                                   "its end point has no cylinder or sphere to roll on"),
                                  (lambda w: rolls_about_its_axis(w, self),
                                   "nothing round at its end point turns about its axis as a wheel does")):
                if drive is not None:
                    break
                kept = [w for w in wheels if rolls(w)]
                if 2 <= len(kept) < len(wheels):
                    drive, _ = differential_drive(kept, self, up)
                    if drive is not None:
                        for w in wheels:
                            if not any(w is k for k in kept):
                                nowheel.append((w["node"], w["motor"], f"HingeJoint motor {w['motor']!r} is no wheel "
                                                f"({reason}): {JOINT_MOVES}", "not rolling as wheels"))
                        wheels = kept
            if drive is None:
                self.warn(node, f"robot {robot.data['name']!r}: no differential drive ({why}); the robot will not move")
                return
            if self.fields(node).node_("physics") is None and up == 2 and "skid_steer" not in drive \
                    and "forward" not in drive:
                # no Physics: Webots moves the robot by its own kinematic rule, with its own axle (wbt/drive.py)
                pair = webots_kinematic_pair(robot.wheels, self)
                if pair is not None and {pair["left_motor"], pair["right_motor"]} == {drive["left_motor"],
                                                                                      drive["right_motor"]}:
                    drive.pop("axle_center", None)
                    # Webots' rule reads the two motors' velocities as they are, whichever way each axis points
                    # (its pair's axes need only be parallel or opposite): a mirrored wheel is not reversed there
                    drive.pop("reversed_motors", None)
                    drive.update(pair)
            robot.data["differential_drive"] = drive
            for w in wheels:      # a wheel's cylinder lying across its hinge's axis: Webots' would not roll
                if not rolls_about_its_axis(w, self, centred=False):
                    self.warn(w["node"], f"HingeJoint motor {w['motor']!r}: its wheel's cylinder lies across the "
                                         f"hinge's axis, not along it; taken as a wheel of radius "
                                         f"{wheel_radius(w['end'], self):g} all the same, where Webots' would not "
                                         "roll on it")
        self._drive_wheels(node, robot, wheels)

    def _drive_wheels(self, node: Node, robot: Owner, wheels: list[dict]) -> None:
        """The drive's wheels are its own: their encoders measure them, their motors' joint fields go;
        their lowest bottom is the drive's ``wheel_bottom`` when the Robot has ``physics`` (Webots'
        gravity drops it, so it settles on the ground at load; one without stays where it is put)."""
        from sensorium.server.world.wbt.drive import wheel_bottom

        up = self._robot_up(robot)
        bottom = (wheel_bottom(wheels, self, up)
                  if self.fields(node).node_("physics") is not None and self._settles_along(up) else None)
        if bottom is not None:
            for key in ("differential_drive", "ackermann_drive", "mecanum_drive", "omni_drive", "steered_drive"):
                if key in robot.data:
                    robot.data[key]["wheel_bottom"] = bottom
            if "ackermann_drive" in robot.data:
                self._car_axles(robot.data["ackermann_drive"], wheels, up)
        for w in wheels:    # the wheels' encoders measure the drive's wheels
            for entry in w.get("sensors", ()):
                entry["motor"] = w["motor"]
        drive_motors = set(drive_motor_names(robot.data))
        for entry in robot.data["devices"]:     # a drive's motor is the drive's: its joint fields are not used
            if entry["device"] == "RotationalMotor" and entry["name"] in drive_motors:
                multiplier = entry.get("multiplier", 1.0)
                for key in JOINT_KEYS:
                    entry.pop(key, None)
                entry["_wheel"] = True
                node_ = self.coupled_nodes.get(id(entry))
                if node_ is not None:      # Webots couples wheels too; a drive here turns each on its own
                    self.warn(node_, f"RotationalMotor {entry['name']!r}: a coupled motor (Webots passes a command "
                                     f"to every motor whose name shares the part before '::', scaled by its "
                                     f"multiplier, here {multiplier:g}) that is a wheel of the robot's drive: not "
                                     "coupled here, it turns on its own commands and getMultiplier answers 1")

    def on_joints(self, robot: dict) -> None:
        """Each shape and device riding on a joint names its motor (``on_joint``), names final; what
        rides on a wheel (the drive's) rides on whatever the wheel rides on (the body, mostly)."""
        def resolved(entry: dict) -> dict | None:
            joint = entry.get("_on_joint")
            while joint is not None and joint.get("_wheel"):
                joint = joint.get("_on_joint")
            return joint

        devices = {d["name"]: d for d in robot["devices"]}
        for entry in [*robot["devices"], *robot.get("shapes", ()), *robot.get("lights", ()),
                      *robot.get("radar_targets", ())]:
            joint = resolved(entry)
            if "of_device" in entry:    # a device's own shapes move as the device does (a joint inside a
                joint = resolved(devices[entry["of_device"]])   # device, a lidar's turret, turns none of them)
            if joint is not None:
                entry["on_joint"] = joint["name"]
        for entry in [*robot["devices"], *robot.get("shapes", ()), *robot.get("lights", ()),
                      *robot.get("radar_targets", ())]:
            entry.pop("_on_joint", None)
        for entry in robot["devices"]:
            entry.pop("_wheel", None)


def drive_motor_names(robot: dict) -> list[str]:
    """The motor names a converted robot's drive uses (a car's non-driven wheels have none)."""
    drive = robot.get("differential_drive") or {}
    skid = drive.get("skid_steer") or {}
    motors = [v for k, v in drive.items() if k in ("left_motor", "right_motor")] + [
        *skid.get("left", ()), *skid.get("right", ())]
    motors += [v for k, v in (robot.get("ackermann_drive") or {}).items() if k.endswith(("_steer", "_wheel"))]
    motors += [v for k, v in (robot.get("mecanum_drive") or {}).items() if k.endswith("_motor")]
    motors += [w["motor"] for w in (robot.get("omni_drive") or {}).get("wheels", ())]
    motors += [w["motor"] for w in (robot.get("steered_drive") or {}).get("wheels", ()) if "motor" in w]
    return [m for m in motors if isinstance(m, str)]


def _limits(motor) -> tuple[float, float]:
    """A motor's (minPosition, maxPosition); (0, 0) is Webots' "no limits"."""
    return motor.num("minPosition", 0.0), motor.num("maxPosition", 0.0)


def _clean_part(p: dict) -> dict:
    out = dict(p)
    if out.get("seen_by") == "both":
        del out["seen_by"]
    return out


EAR_CLIP_WORLD = 400_000     # corners² a world's concave IndexedFaceSet polygons of 5 or more corners may take
                             # (ear clipping is quadratic: six 256-corner polygons, ~0.15 s; quads are cut at once)


def fan_corners(index: list[int]) -> np.ndarray:
    """An IndexedFaceSet's polygons (``index`` positions between -1s) fan-triangulated, as Webots
    does: per triangle, the positions in ``index`` of its three corners (first, k, k + 1), shape
    (n, 3); polygons of fewer than three corners give none."""
    idx = np.append(np.asarray(index, dtype=np.int64), -1)
    ends = np.flatnonzero(idx < 0)
    starts = np.concatenate(([0], ends[:-1] + 1))
    per = np.maximum(ends - starts - 2, 0)              # triangles per polygon
    first = np.repeat(starts, per)
    k = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per) + 1
    return np.stack([first, first + k, first + k + 1], axis=1)


def polygon_corners(index: list[int], points: list[float], budget: list[int]) -> tuple[np.ndarray, int]:
    """An IndexedFaceSet's triangles as Webots' GLU tessellator covers its polygons: :func:`fan_corners`,
    with each concave polygon (a corner turning against its normal) cut along its diagonals instead,
    so no triangle covers what lies outside it (an arena wall's top face drawn as one polygon, the
    outer square and the inner one joined by a slit, covers the ring only, not the arena). A quad
    with one reflex corner is cut along the diagonal from that corner (all such quads at once);
    a larger polygon into ears, while ``budget[0]`` (the corners² left for ear clipping, which is
    quadratic) lasts and it has at most ``EAR_CLIP_CORNERS`` corners, else it stays fanned. A quad
    turning against itself twice (crossed, or folded out of its plane) keeps its fan. ``points``
    are the coordinates (x y z ...): convexity and cuts are the same under any scale. Returns the
    corners and how many concave polygons stayed fanned for size or budget."""
    corners = fan_corners(index)
    idx = np.append(np.asarray(index, dtype=np.int64), -1)
    ends = np.flatnonzero(idx < 0)
    starts = np.concatenate(([0], ends[:-1] + 1))
    counts = ends - starts
    big = counts >= 4                                   # a triangle is convex
    if not big.any():
        return corners, 0
    xyz = np.asarray(points, dtype=np.float64)
    xyz = xyz[:len(xyz) - len(xyz) % 3].reshape(-1, 3)
    bs, bc = starts[big], counts[big]
    at = np.repeat(bs, bc) + np.arange(int(bc.sum())) - np.repeat(np.cumsum(bc) - bc, bc)   # their corners
    vertex = idx[at]
    if vertex.max(initial=0) >= len(xyz):              # an index past the points: refused later, by value
        return corners, 0
    reflex = reflex_corners(xyz[vertex], bc, np.cumsum(bc) - bc)
    per = np.add.reduceat(reflex.astype(np.int64), np.cumsum(bc) - bc)
    if not per.any():
        return corners, 0
    n_tri = np.maximum(counts - 2, 0)
    tri_start = (np.cumsum(n_tri) - n_tri)[big]
    quads = np.flatnonzero((bc == 4) & (per == 1))
    if len(quads):                                      # the diagonal from the reflex corner r: (r, r+1, r+2), (r, r+2, r+3)
        r = reflex.reshape(-1)[(np.cumsum(bc) - bc)[quads][:, None] + np.arange(4)].argmax(axis=1)
        cut = bs[quads][:, None, None] + (r[:, None, None] + np.array([[[0, 1, 2], [0, 2, 3]]])) % 4
        corners[(tri_start[quads][:, None] + np.arange(2)).reshape(-1)] = cut.reshape(-1, 3)
    fanned = 0
    for k in np.flatnonzero((bc > 4) & (per > 0)):
        s, n = int(bs[k]), int(bc[k])
        if n > EAR_CLIP_CORNERS or budget[0] < n * n:
            fanned += 1
            continue
        budget[0] -= n * n
        ears = ear_clip(xyz[idx[s:s + n]])
        if ears is None:                                # self-crossing: no ear to cut, fanned as before
            continue
        corners[tri_start[k]:tri_start[k] + n - 2] = ears + s
    return corners, fanned


def _pick(values: np.ndarray | list[int], corners: np.ndarray) -> np.ndarray | list[list[int]]:
    """``values`` at each triangle's corner positions: an int64 array (n, 3) (lists of Python ints
    for an index beyond 64 bits, which the loader refuses by value)."""
    if not len(corners):
        return []
    try:
        return np.asarray(values, dtype=np.int64)[corners]
    except OverflowError:       # an index beyond 64 bits: refused later, by value
        return [[values[a], values[b], values[c]] for a, b, c in corners.tolist()]


def _same(a: np.ndarray | list[int], b: np.ndarray | list[int]) -> bool:
    """Two coordIndex values equal (arrays or, beyond 64 bits, lists)."""
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        return a.shape == b.shape and bool(np.array_equal(a, b))
    return list(a) == list(b)


def strip_origins(data: Any, path: str, origin: dict[str, tuple[int, int, str]]) -> Any:
    """Remove the ``_at`` bookkeeping keys, recording converted path → (line, col, node type)."""
    if isinstance(data, dict):
        if "_at" in data:
            origin[path] = data["_at"]
        return {k: strip_origins(v, f"{path}.{k}" if path else k, origin) for k, v in data.items() if k != "_at"}
    if isinstance(data, list):
        kinds = set(map(type, data))            # a mesh's numbers: copied at C speed (no dict inside)
        if _flat(kinds):
            return list(data)
        if kinds == {list} and _flat(set(map(type, itertools.chain.from_iterable(data)))):
            return list(map(list, data))
        return [strip_origins(v, f"{path}[{i}]", origin) for i, v in enumerate(data)]
    return data


def _flat(kinds: set[type]) -> bool:
    """No dict or list among these types (what strip_origins would walk into)."""
    return not any(issubclass(k, (dict, list)) for k in kinds)


def _consuming_motors(node: Node) -> bool:
    """Whether a motor inside ``node`` consumes energy in Webots (consumptionFactor > 0; 10 by default)."""
    stack = _sub_nodes(node)
    while stack:
        v = stack.pop()
        if v.type in ("RotationalMotor", "LinearMotor"):
            factor = v.fields.get("consumptionFactor", 10.0)
            if not isinstance(factor, (int, float)) or factor > 0:
                return True
        stack += _sub_nodes(v)
    return False
