"""Parsed .wbt tree → a Sensorium world (a plain dict in the world-file format, then validated).

Flattening happens here: Pose/Transform/Group frames are composed into the poses of shapes,
devices and lights; a top-level Solid becomes a world solid, a Solid inside it one of its
``children``; everything inside a Robot (nested Solids, joint end points, device bodies) becomes a
body shape or a device of the robot, placed relative to the robot. Two motorised HingeJoint wheels
on one axle become the robot's kinematic ``differential_drive``.

Poses keep the file's exact axis-angle values when only one level rotates (so a converted world
reads bit for bit like its hand-written twin); a pose composed of several rotations is written as
a quaternion.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion
from sensorium.server.world.wbt import fields as fx
from sensorium.server.world.wbt.fields import Fields
from sensorium.server.world.wbt.parser import Node, WbtFile, WbtSyntaxError
from sensorium.server.world.wbt.protos import BUILTIN_PROTOS

MAX_PARTS = 200_000     # shapes, devices and lights after DEF/USE expansion
MAX_VISITS = 2_000_000  # nodes walked after DEF/USE expansion (empty groups USEd over and over)

SKIPPED = {"Viewpoint", "Background", "TexturedBackground", "Fog", "Physics", "ImmersionProperties",
           "ContactProperties", "Damping", "Brake", "Muscle", "Propeller", "Skin", "CadShape"}
# devices not simulated here; they are Solids, so their shapes stay part of the robot's body
OTHER_DEVICES = {"Camera", "RangeFinder", "Display", "Speaker", "Microphone", "Emitter", "Receiver", "GPS",
                 "Compass", "Accelerometer", "Gyro", "InertialUnit", "TouchSensor", "Pen", "Charger",
                 "Connector", "Radar", "Altimeter", "VacuumGripper", "Radio", "Track"}
GEOMETRIES = {"Box", "Sphere", "Cylinder", "Capsule", "Plane", "IndexedFaceSet", "Mesh"}
LIGHTS = {"PointLight", "SpotLight", "DirectionalLight"}
SENSORS = {"DistanceSensor", "LightSensor", "Lidar", "PositionSensor", "LED"}
JOINTS = {"HingeJoint", "Hinge2Joint", "SliderJoint", "BallJoint"}
MOTORS = {"RotationalMotor", "LinearMotor"}


@dataclass(frozen=True)
class Frame:
    """Rigid transform with a uniform scale: x_parent = R (s x) + t; ``aa`` = the exact axis-angle
    of R when known (None once two rotations were composed)."""

    rotation: np.ndarray
    translation: np.ndarray
    scale: float = 1.0
    aa: tuple[float, float, float, float] | None = (0.0, 0.0, 1.0, 0.0)

    @staticmethod
    def identity() -> Frame:
        return Frame(np.eye(3), np.zeros(3))

    def then(self, translation, rotation, scale: float = 1.0) -> Frame:
        r2 = axis_angle_matrix(rotation[:3], rotation[3]) if rotation[3] != 0.0 else np.eye(3)
        t = self.rotation @ (self.scale * np.asarray(translation, dtype=np.float64)) + self.translation
        aa: tuple[float, ...] | None
        if self.aa is not None and self.aa[3] == 0.0:
            aa = tuple(rotation)
        elif rotation[3] == 0.0:
            aa = self.aa
        else:
            aa = None
        return Frame(self.rotation @ r2, t, self.scale * scale, aa)  # type: ignore[arg-type]

    def apply(self, p) -> list[float]:
        return [float(v) for v in self.rotation @ (self.scale * np.asarray(p, dtype=np.float64)) + self.translation]

    def pose(self) -> dict:
        out: dict[str, Any] = {"translation": [float(v) for v in self.translation]}
        if self.aa is None:
            out["quaternion"] = list(matrix_quaternion(self.rotation))
        elif self.aa[3] != 0.0:
            out["rotation"] = list(self.aa)
        return out

    def key(self) -> bytes:
        return self.rotation.tobytes() + self.translation.tobytes() + np.float64(self.scale).tobytes()


@dataclass
class Owner:
    """What shapes, lights and devices found now belong to: the world, a solid or a robot."""

    kind: str                      # "world", "solid", "robot"
    data: dict
    parts: list[dict] = field(default_factory=list)
    keys: dict[tuple, dict] = field(default_factory=dict)      # visual parts by (geometry, frame)
    wheels: list[dict] = field(default_factory=list)           # motorised hinges (robots)


class Converter:
    def __init__(self, wbt: WbtFile, source: str, search: Any = None):
        self.wbt = wbt
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
        self.defs: set[str] = set()        # DEF names kept (def_name)
        self.textured: dict[int, tuple[int, int, str]] = {}   # textures not loaded → (line, column, why)
        self.robot_fields = set(wm.Robot.model_fields)
        self.device_kinds = {k for k in SENSORS if hasattr(wm, k)}

    # ------------------------------------------------------------ messages
    def warn(self, node: Node, message: str) -> None:
        self.warnings.append(f"{self.source}:{node.line}:{node.col}: {message}")

    def fields(self, node: Node) -> Fields:
        return Fields(node, self.source)

    def error(self, node: Node, message: str) -> WbtSyntaxError:
        return WbtSyntaxError(self.source, node.line, node.col, message)

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
        for node in self.wbt.nodes:
            self.visit(node, Frame.identity(), world, top=True)
        if world.parts:   # shapes outside any Solid: one solid holding them (visual only, as in Webots)
            self.world["solids"].append(self.solid_dict(world, {"name": self.unique_name("shapes")}))
        if self.textured:   # textures not loaded: one line (world/textures.py says why each is refused)
            (line, col, why), n = min(self.textured.values()), len(self.textured)
            self.warnings.append(f"{self.source}:{line}:{col}: {n} texture{'s' if n > 1 else ''} not loaded (first: {why}); "
                                 "read as Webots reads a texture it cannot load: an Appearance as its material's "
                                 "diffuseColor, a PBRAppearance as its baseColor")
        if self.skipped:
            listed = ", ".join(f"{k} x{v}" if v > 1 else k for k, v in sorted(self.skipped.items()))
            self.warnings.append(f"{self.source}: skipped nodes that do not matter to these sensors: {listed}")
        return {k: v for k, v in self.world.items() if v}

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
        self.world["world_info"] = info

    # ------------------------------------------------------------ the walk
    def visit(self, node: Node, frame: Frame, owner: Owner, top: bool = False) -> None:
        self.walk(node)
        t = node.type
        f = self.fields(node)
        self.typos(node)
        if t == "WorldInfo":
            if not top:
                raise self.error(node, "WorldInfo must be a top-level node")
            self.world_info(node)
        elif t in SKIPPED:
            self.skipped[t] += 1
        elif t in OTHER_DEVICES:
            self.skipped[t] += 1
            if owner.kind == "robot":
                self.solid_contents(node, self.child_frame(node, frame), owner)
        elif t == "Group":
            for child in f.nodes("children"):
                self.visit(child, frame, owner)
        elif t in ("Pose", "Transform"):
            inner = self.child_frame(node, frame)
            for child in f.nodes("children"):
                self.visit(child, inner, owner)
        elif t == "Shape":
            self.shape(node, frame, owner, seen_by="visual")
        elif t in LIGHTS:
            self.light(node, frame, owner)
        elif t == "Robot":
            if owner.kind != "world":
                self.warn(node, "a Robot inside a Solid or another Robot is not supported: skipped")
            elif frame.scale != 1.0:
                self.warn(node, "a Robot inside a scaled Transform is not supported: skipped")
            else:
                self.robot(node, frame)
        elif t == "Solid":
            self.solid(node, frame, owner)
        elif t in SENSORS or t in MOTORS:
            self.device(node, frame, owner)
        elif t in JOINTS:
            self.joint(node, frame, owner)
        elif t in BUILTIN_PROTOS:
            system = self.world["world_info"].get("coordinate_system", "ENU")
            expanded = BUILTIN_PROTOS[t](node, f, system)
            expanded.def_name = node.def_name
            self.visit(expanded, frame, owner, top)
        elif t in GEOMETRIES:
            self.warn(node, f"{t} outside a Shape or boundingObject: ignored")
        else:
            self.warn(node, f"{t}: not a built-in node or PROTO here; skipped (with everything inside it). "
                            f"Built-in PROTOs: {', '.join(sorted(BUILTIN_PROTOS))}")

    def appearance_note(self, node: Node, message: str) -> None:
        if message.startswith("texture: "):   # one summary line for all textures not loaded
            if id(node) not in self.textured:
                self.textured[id(node)] = (node.line, node.col, message[len("texture: "):])
        else:
            self.warn(node, message)

    def def_name(self, node: Node, data: dict) -> None:
        """Keep a robot's or top-level solid's DEF (getFromDef); a DEF reused later keeps its first node."""
        if node.def_name is not None and node.def_name not in self.defs:
            self.defs.add(node.def_name)
            data["def_name"] = node.def_name

    def typos(self, node: Node) -> None:
        if id(node) in self.checked:
            return
        self.checked.add(id(node))
        for name, meant in fx.field_typos(node):
            line, col = node.field_pos.get(name, (node.line, node.col))
            self.warnings.append(f"{self.source}:{line}:{col}: {node.type}.{name}: not a {node.type} field, "
                                 f"ignored (did you mean {meant}?)")

    def child_frame(self, node: Node, frame: Frame) -> Frame:
        f = self.fields(node)
        rotation = f.vec("rotation", (0.0, 0.0, 1.0, 0.0))
        if rotation[3] != 0.0 and math.hypot(*rotation[:3]) == 0.0:
            raise f.error("rotation", "the rotation axis must not be zero")
        scale = 1.0
        if node.type == "Transform":
            sx, sy, sz = f.vec("scale", (1.0, 1.0, 1.0))
            if not (sx == sy == sz) or sx <= 0:
                raise f.error("scale", f"only a uniform positive scale is supported, got {sx} {sy} {sz}")
            scale = sx
        return frame.then(f.vec("translation", (0.0, 0.0, 0.0)), rotation, scale)

    # ------------------------------------------------------------ shapes
    def shape(self, node: Node, frame: Frame, owner: Owner, seen_by: str) -> None:
        f = self.fields(node)
        gnode = f.node_("geometry") if node.type == "Shape" else node
        if gnode is None:
            return
        if gnode.type not in GEOMETRIES:
            self.warn(gnode, f"geometry {gnode.type} is not supported (Box, Sphere, Cylinder, Capsule, Plane, "
                             "IndexedFaceSet, Mesh): ignored")
            return
        self.tick(gnode)
        for checked in (node, gnode, f.node_("appearance") if node.type == "Shape" else None):
            if checked is not None:
                self.typos(checked)
                material = checked.fields.get("material") if checked.type == "Appearance" else None
                if isinstance(material, Node):
                    self.typos(material)
        geometry = self.geometry(gnode, frame.scale)
        key = (id(gnode), frame.key())
        if seen_by == "bounding" and key in owner.keys:   # the same geometry seen by both kinds of ray
            owner.keys[key]["seen_by"] = "both"
            return
        part: dict[str, Any] = {"pose": frame.pose(), "geometry": geometry, "seen_by": seen_by}
        if seen_by == "visual":
            app = fx.appearance(f.node_("appearance"), self.source, self.appearance_note)
            if app is not None:
                part["appearance"] = app
            owner.keys[key] = part
        part["_at"] = (gnode.line, gnode.col, gnode.type)
        owner.parts.append(part)

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
            inner = self.child_frame(node, frame)
            for child in f.nodes("children"):
                self.bounding(child, inner, owner)
        else:
            self.warn(node, f"{node.type} in a boundingObject: ignored")

    def geometry(self, node: Node, s: float) -> dict:
        f = self.fields(node)
        t = node.type
        if t == "Box":
            return {"type": "box", "size": [v * s for v in f.vec("size", (2.0, 2.0, 2.0))]}
        if t == "Sphere":
            return {"type": "sphere", "radius": f.num("radius", 1.0) * s}
        if t in ("Cylinder", "Capsule"):
            if not all(f.flag(k, True) for k in ("bottom", "side", "top")):
                self.warn(node, f"{t} with bottom/side/top FALSE: rays see the whole closed {t.lower()}")
            return {"type": t.lower(), "radius": f.num("radius", 1.0) * s, "height": f.num("height", 2.0) * s}
        if t == "Plane":
            return {"type": "plane", "size": [v * s for v in f.vec("size", (1.0, 1.0))]}
        if t == "Mesh":
            urls = f.strings("url")
            if not urls:
                raise f.error("url", "a Mesh needs a url")
            if "://" in urls[0]:
                raise f.error("url", f"only local mesh files are supported, got {urls[0]!r}")
            return {"type": "mesh", "url": urls[0], "scale": [s, s, s]}
        # IndexedFaceSet: polygons separated by -1, fan-triangulated (texCoordIndex alongside)
        coord = f.node_("coord")
        points = self.fields(coord).rows("point", 3, []) if coord is not None else []
        index = [int(i) for i in f.numbers("coordIndex")]
        tex, tex_index = fx.tex_coords(node, f, len(index), self.warn)
        faces: list[list[int]] = []
        tex_faces: list[list[int]] = []
        poly: list[int] = []
        for n_i, i in enumerate([*index, -1]):
            if i >= 0:
                poly.append(n_i)
                continue
            for k in range(1, len(poly) - 1):
                corners = (poly[0], poly[k], poly[k + 1])
                faces.append([index[c] for c in corners])
                if tex_index is not None:
                    tex_faces.append([tex_index[c] for c in corners])
            poly = []
        if not faces:
            raise f.error("coordIndex", "an IndexedFaceSet needs at least one polygon")
        out = {"type": "triangles", "vertices": [[v * s for v in p] for p in points], "faces": faces}
        if tex is not None:
            out["tex_coords"], out["tex_coord_faces"] = tex, tex_faces
        return out

    # ------------------------------------------------------------ lights
    def light(self, node: Node, frame: Frame, owner: Owner) -> None:
        self.tick(node)
        data = fx.light(node, self.fields(node))
        if "location" in data:
            data["location"] = frame.apply(data["location"])
        if node.type == "SpotLight":
            data["direction"] = [float(v) for v in frame.rotation @ np.asarray(data["direction"])]
        data["_at"] = (node.line, node.col, node.type)
        owner.data.setdefault("lights", []).append(data) if owner.kind != "world" else self.world["lights"].append(data)

    # ------------------------------------------------------------ solids and robots
    def solid(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        inner = self.child_frame(node, frame)
        if owner.kind == "robot":   # part of the robot's body
            self.solid_contents(node, inner, owner)
            return
        if frame.scale != 1.0:
            raise self.error(node, "a Solid inside a scaled Transform is not supported")
        name = f.string("name", "solid")
        data = {"name": self.unique_name(name) if owner.kind == "world" else name, "pose": inner.pose()}
        if owner.kind == "world":
            self.def_name(node, data)
        if owner.kind == "world" and data["name"] != name:
            self.warn(node, f"solid name {name!r} used before: renamed {data['name']!r}")
        mine = Owner("solid", data)
        self.solid_contents(node, Frame.identity(), mine)
        out = self.solid_dict(mine, data)
        out["_at"] = (node.line, node.col, node.type)
        if owner.kind == "world":
            self.world["solids"].append(out)
        else:
            owner.data.setdefault("children", []).append(out)

    def solid_contents(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        for child in f.nodes("children"):
            self.visit(child, frame, owner)
        self.bounding(f.node_("boundingObject"), frame, owner)

    def solid_dict(self, owner: Owner, data: dict) -> dict:
        if owner.parts:
            data["shapes"] = [_clean_part(p) for p in owner.parts]
        return data

    def robot(self, node: Node, frame: Frame) -> None:
        f = self.fields(node)
        inner = self.child_frame(node, frame)
        name = f.string("name", "robot")
        unique = self.unique_robot(name)
        if unique != name:
            self.warn(node, f"robot name {name!r} used before: renamed {unique!r}")
        data: dict[str, Any] = {"name": unique, "pose": inner.pose(),
                                "synchronization": f.flag("synchronization", True), "devices": []}
        self.def_name(node, data)
        controller = f.string("controller", "<extern>")
        if controller in ("", "void"):                      # Webots' other ways of saying "no controller"
            controller = "<none>"
        if controller not in ("<extern>", "<none>"):
            self.warn(node, f"Robot {unique!r}: controller {controller!r} is not started here; run it with "
                            f"`sensorium controller` (the robot is an <extern> robot)")
            controller = "<extern>"
        extras = {"controller": controller, "supervisor": f.flag("supervisor", False),
                  "custom_data": f.string("customData", ""), "model": f.string("model", "")}
        defaults = {"controller": "<extern>", "supervisor": False, "custom_data": "", "model": ""}
        for key, value in extras.items():
            if key in self.robot_fields:
                if key != "controller" or f.has("controller"):
                    data[key] = value
            elif value != defaults[key]:
                self.warn(node, f"Robot field {key}: not supported by this version; ignored")
        data["_at"] = (node.line, node.col, node.type)
        mine = Owner("robot", data)
        self.solid_contents(node, Frame.identity(), mine)
        self.drive(node, mine)
        if mine.parts:
            data["shapes"] = [_clean_part(p) for p in mine.parts]
        self.unique_devices(data)
        if not data["devices"]:
            del data["devices"]
        self.world["robots"].append(data)

    def unique_devices(self, robot: dict) -> None:
        """Device names address topics and services, so a repeated one gets a suffix (Webots warns
        and its getDevice returns the first); the wheel motors' names count too."""
        drive = robot.get("differential_drive") or {}
        seen: Counter[str] = Counter(v for k, v in drive.items() if k in ("left_motor", "right_motor"))
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
            self.warn(node, f"{node.type} outside a Robot: skipped (devices belong to robots)")
            return
        self.tick(node)
        inner = self.child_frame(node, frame)
        if node.type in MOTORS:   # a motor outside a joint's device list
            self.warn(node, f"{node.type} outside a joint: skipped")
            return
        if node.type not in self.device_kinds:
            self.warn(node, f"{node.type}: device kind not supported by this version; skipped")
        else:
            data = {"name": f.string("name", fx.DEVICE_NAMES[node.type]), "pose": inner.pose(), **fx.device(node, f)}
            data["_at"] = (node.line, node.col, node.type)
            if node.type == "Lidar" and f.node_("rotatingHead") is not None:
                self.skipped["Lidar.rotatingHead"] += 1
            owner.data["devices"].append(data)
        self.solid_contents(node, inner, owner)

    def joint(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        end = f.node_("endPoint")
        motors = [d for d in f.nodes("device") if d.type in MOTORS]
        sensors = [d for d in f.nodes("device") if d.type == "PositionSensor"]
        if owner.kind == "robot" and node.type == "HingeJoint" and motors:
            params = f.node_("jointParameters")
            if params is not None:
                self.typos(params)
            pf = self.fields(params) if params is not None else None
            axis = pf.vec("axis", (1.0, 0.0, 0.0)) if pf else (1.0, 0.0, 0.0)
            anchor = pf.vec("anchor", (0.0, 0.0, 0.0)) if pf else (0.0, 0.0, 0.0)
            m = self.fields(motors[0])
            centre = anchor
            if end is not None and end.type == "Solid":
                centre = self.fields(end).vec("translation", (0.0, 0.0, 0.0))
            owner.wheels.append({"node": node, "motor": m.string("name", "rotational motor"),
                                 "max_velocity": m.num("maxVelocity", 10.0),
                                 "axis": frame.rotation @ np.asarray(axis), "anchor": np.asarray(frame.apply(anchor)),
                                 "centre": np.asarray(frame.apply(centre)),
                                 "end": end, "frame": frame, "sensors": sensors})
        elif motors:
            self.warn(node, f"{node.type} motor(s) not part of a wheel: skipped (joints do not move here)")
        if sensors and not (owner.kind == "robot" and node.type == "HingeJoint" and motors):
            self.warn(node, "PositionSensor on a joint without a drive wheel motor: skipped")
        if end is not None:
            if end.type == "SolidReference":
                return
            self.visit(end, frame, owner)

    def drive(self, node: Node, robot: Owner) -> None:
        from sensorium.server.world.wbt.drive import differential_drive

        wheels = robot.wheels
        if not wheels:
            return
        drive, why = differential_drive(wheels, self)
        if drive is None:
            self.warn(node, f"robot {robot.data['name']!r}: no differential drive ({why}); the robot will not move")
            return
        robot.data["differential_drive"] = drive
        if "PositionSensor" in self.device_kinds:
            for w in wheels:
                for s in w["sensors"]:
                    sf = self.fields(s)
                    robot.data["devices"].append({"name": sf.string("name", "position sensor"), "device": "PositionSensor",
                                                  "motor": w["motor"], "noise": sf.num("noise", 0.0),
                                                  "resolution": sf.num("resolution", -1.0),
                                                  "_at": (s.line, s.col, s.type)})
        elif any(w["sensors"] for w in wheels):
            self.warn(node, "PositionSensor: device kind not supported by this version; skipped")


def _clean_part(p: dict) -> dict:
    out = dict(p)
    if out.get("seen_by") == "both":
        del out["seen_by"]
    return out


def strip_origins(data: Any, path: str, origin: dict[str, tuple[int, int, str]]) -> Any:
    """Remove the ``_at`` bookkeeping keys, recording converted path → (line, col, node type)."""
    if isinstance(data, dict):
        if "_at" in data:
            origin[path] = data["_at"]
        return {k: strip_origins(v, f"{path}.{k}" if path else k, origin) for k, v in data.items() if k != "_at"}
    if isinstance(data, list):
        return [strip_origins(v, f"{path}[{i}]", origin) for i, v in enumerate(data)]
    return data
