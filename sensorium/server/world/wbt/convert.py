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
           "ContactProperties", "Damping", "Muscle", "Propeller", "CadShape"}
# devices not simulated here: listed in the robot's devices (Webots' indices) as UnsimulatedDevice;
# the Solid ones keep their shapes as part of the robot's body (Charger and Track are Solids, not devices)
OTHER_DEVICES = {"Display", "Speaker", "Microphone", "Emitter", "Receiver", "GPS",
                 "Compass", "Accelerometer", "Gyro", "InertialUnit", "TouchSensor", "Pen", "Charger",
                 "Connector", "Radar", "Altimeter", "VacuumGripper", "Radio", "Track", "Skin"}
# Webots' default device names (the ``name`` field's default of each node)
OTHER_NAMES = {"RangeFinder": "range-finder", "InertialUnit": "inertial unit", "TouchSensor": "touch sensor",
               "VacuumGripper": "vacuum gripper", "LinearMotor": "linear motor", "GPS": "gps"}
GEOMETRIES = {"Box", "Sphere", "Cylinder", "Capsule", "Plane", "IndexedFaceSet", "Mesh"}
LIGHTS = {"PointLight", "SpotLight", "DirectionalLight"}
SENSORS = {"DistanceSensor", "LightSensor", "Lidar", "PositionSensor", "LED", "RangeFinder", "Camera"}
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

    def compose(self, inner: Frame) -> Frame:
        """``inner`` (a frame given relative to this one) in this frame's parent."""
        aa: tuple[float, float, float, float] | None
        if self.aa is not None and self.aa[3] == 0.0:
            aa = inner.aa
        elif inner.aa is not None and inner.aa[3] == 0.0:
            aa = self.aa
        else:
            aa = None
        t = self.rotation @ (self.scale * inner.translation) + self.translation
        return Frame(self.rotation @ inner.rotation, t, self.scale * inner.scale, aa)

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
    placed: Frame = field(default_factory=Frame.identity)      # the owner's frame in the world


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
        self.textured: dict[int, tuple[int, int, str, str]] = {}   # textures not loaded → (line, column, why)
        self.robot_fields = set(wm.Robot.model_fields)
        self.device_kinds = {k for k in SENSORS if hasattr(wm, k)}
        self.instances: list[tuple[str, tuple[str, int, int]]] = []   # PROTO instances being walked (name, at)
        self.asset_files: set[Path] = set()   # asset files outside the world's folder this world may read
        self.dropped: list[str] = []      # robots, sensor devices and sensor-visible shapes lost (messages)

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

    def drop(self, node: Node, message: str) -> None:
        """A loss that changes what sensors read (a robot, a sensor device, a shape sensors see): a
        warning that ``validate`` counts as an error unless ``--allow-skipped``."""
        text = f"{self.where(node)}: {message}"
        self.warnings.append(text)
        self.dropped.append(text)

    def fields(self, node: Node) -> Fields:
        return Fields(node, node.source or self.source)

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
        for node in self.wbt.nodes:
            self.visit(node, Frame.identity(), world, top=True)
        if world.parts:   # shapes outside any Solid: one solid holding them (visual only, as in Webots)
            self.world["solids"].append(self.solid_dict(world, {"name": self.unique_name("shapes")}))
        if self.textured:   # textures not loaded: one line (world/textures.py says why each is refused)
            (_, _, where, why), n = min(self.textured.values()), len(self.textured)
            self.warnings.append(f"{where}: {n} texture{'s' if n > 1 else ''} not loaded (first: {why}); "
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
        if node.proto is not None and node.instance_at is not None:
            self.instances.append((node.proto, node.instance_at))
            try:
                self.visit_node(node, frame, owner, top)
            finally:
                self.instances.pop()
        else:
            self.visit_node(node, frame, owner, top)

    def visit_node(self, node: Node, frame: Frame, owner: Owner, top: bool = False) -> None:
        self.walk(node)
        t = node.type
        f = self.fields(node)
        self.typos(node)
        if t == "WorldInfo":
            if not top:
                raise self.error(node, "WorldInfo must be a top-level node")
            self.world_info(node)
        elif t == "Background" and top and f.has("skyColor"):     # what cameras see past everything
            sky = f.rows("skyColor", 3, [(0.0, 0.0, 0.0)])
            self.world["background"] = {"sky_color": list(sky[0]) if sky else [0.0, 0.0, 0.0]}
            self.skipped[t] += 1     # its other fields (textures, luminosity) are not read
        elif t in SKIPPED:
            self.skipped[t] += 1
        elif t in OTHER_DEVICES:
            if owner.kind == "robot":
                inner = self.child_frame(node, frame)
                if t in wm.DEVICE_TYPES:     # listed (simulated kinds take their schema defaults)
                    self.tick(node)
                    self.unsimulated(node, inner, owner)
                self.solid_contents(node, inner, owner)
            else:
                self.skipped[t] += 1
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
            name = self.fields(node).string("name", "robot")
            if owner.kind == "robot":
                self.drop(node, f"Robot {name!r} inside robot {owner.data['name']!r}: a robot riding on another "
                                "robot is not supported here; dropped with everything inside it")
            elif frame.scale != 1.0 or owner.placed.scale != 1.0:
                self.drop(node, f"Robot {name!r} inside a scaled Transform: Webots does not allow a Solid "
                                "(so a Robot) under a Transform that scales; dropped")
            else:     # at the top or nested in solids and groups: a robot placed where they put it
                self.robot(node, owner.placed.compose(frame))
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
            self.drop(node, f"{t}: not a built-in node or PROTO here; skipped (with everything inside it). "
                            f"Built-in PROTOs: {', '.join(sorted(BUILTIN_PROTOS))}")

    def appearance_note(self, node: Node, message: str) -> None:
        if message.startswith("texture: "):   # one summary line for all textures not loaded
            if id(node) not in self.textured:
                self.textured[id(node)] = (node.line, node.col, self.where(node), message[len("texture: "):])
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
            self.warnings.append(f"{self.where(node, (line, col))}: {node.type}.{name}: not a {node.type} field, "
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
        if geometry is None:
            return
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
        part["_at"] = self.at(gnode)
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

    def asset(self, node: Node, url: str) -> str | None:
        """The url a converted world names for an asset ``url`` written in ``node``'s file: as written
        when the world file names a local file (the loader confines it to the world's folder); else
        (a PROTO's url, relative to the PROTO file; ``webots://`` or Webots' GitHub urls, from the
        installation) the local file it names, which must lie in the Webots installation, a
        --proto-path folder or the project of the PROTO file that names it (read only). None: the
        file is missing (a warning naming it: the shape is left out)."""
        from sensorium.server.world.proto import ProtoError, asset_roots, resolve_url

        src = node.source or self.source
        if src == self.source and "://" not in url:
            if not (Path(self.source).resolve().parent / url).is_file() and "\0" not in url:
                self.warn(node, f"mesh file {url!r} not found (relative to the world file): this shape is left out, "
                                "rays do not see it")
                return None
            return url
        if self.search is None:
            self.warn(node, f"mesh url {url!r}: no PROTO search places to resolve it; this shape is left out")
            return None
        try:
            path = resolve_url(url, src, self.search).resolve()
        except ProtoError as exc:
            self.warn(node, f"mesh file {exc.message}; this shape is left out, rays do not see it")
            return None
        except (OSError, ValueError) as exc:
            self.warn(node, f"mesh url {url!r} cannot be resolved ({exc}); this shape is left out")
            return None
        roots = [*asset_roots(self.search), Path(src).resolve().parent.parent, Path(self.source).resolve().parent]
        if not any(path.is_relative_to(r) for r in roots):
            self.warn(node, f"mesh url {url!r} names a file outside the Webots installation, the --proto-path "
                            "folders and the PROTO's project: refused, this shape is left out")
            return None
        if not path.is_file():
            self.warn(node, f"mesh file {url!r} not found: this shape is left out, rays do not see it")
            return None
        self.asset_files.add(path)
        return str(path)

    def geometry(self, node: Node, s: float) -> dict | None:
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
            url = self.asset(node, urls[0].replace("\\", "/"))
            if url is None:
                return None
            return {"type": "mesh", "url": url, "scale": [s, s, s]}
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
        data["_at"] = self.at(node)
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
            colors = f.rows("recognitionColors", 3, [])        # what cameras with a Recognition node report
            if colors:
                data["recognition_colors"] = [list(c) for c in colors]
            if f.string("model", ""):
                data["model"] = f.string("model", "")
        elif f.has("recognitionColors") and f.rows("recognitionColors", 3, []):
            self.warn(node, f"Solid {name!r}: recognitionColors of a nested solid are not read (give them to the "
                            "top-level solid); ignored")
        if owner.kind == "world" and data["name"] != name:
            self.warn(node, f"solid name {name!r} used before: renamed {data['name']!r}")
        mine = Owner("solid", data, placed=owner.placed.compose(inner))
        self.solid_contents(node, Frame.identity(), mine)
        out = self.solid_dict(mine, data)
        out["_at"] = self.at(node)
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
        colors = f.rows("recognitionColors", 3, [])
        if colors:
            data["recognition_colors"] = [list(c) for c in colors]
        data["_at"] = self.at(node)
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
        listed = {d["name"] for d in robot["devices"] if d["device"] == "RotationalMotor"}
        seen: Counter[str] = Counter(v for k, v in drive.items() if k in ("left_motor", "right_motor") and v not in listed)
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
            self.drop(node, f"{node.type}: device kind not supported by this version; skipped")
        else:
            data = {"name": f.string("name", fx.DEVICE_NAMES[node.type]), "pose": inner.pose(), **fx.device(node, f)}
            model = f.string("model", "")
            if model:
                data["model"] = model
            data["_at"] = self.at(node)
            if node.type == "Lidar" and f.node_("rotatingHead") is not None:
                self.skipped["Lidar.rotatingHead"] += 1
            owner.data["devices"].append(data)
        self.solid_contents(node, inner, owner)

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
        data["_at"] = self.at(node)
        owner.data["devices"].append(data)
        return data

    def joint_devices(self, node: Node, owner: Owner) -> tuple[list[dict], list[dict]]:
        """A joint's devices in its ``device`` order (Webots lists them before the end point's):
        (motor entries, position sensor entries)."""
        motors, sensors = [], []
        for d in self.fields(node).nodes("device"):
            self.walk(d)
            self.tick(d)
            if d.type == "RotationalMotor":
                entry = {"name": self.fields(d).string("name", "rotational motor"), "device": "RotationalMotor",
                         "_at": self.at(d)}
                owner.data["devices"].append(entry)
                motors.append(entry)
            elif d.type == "PositionSensor":
                sf = self.fields(d)
                entry = {"name": sf.string("name", "position sensor"), "device": "PositionSensor",
                         "noise": sf.num("noise", 0.0), "resolution": sf.num("resolution", -1.0), "_at": self.at(d)}
                owner.data["devices"].append(entry)
                sensors.append(entry)
            elif d.type in ("LinearMotor", "Brake"):
                self.unsimulated(d, Frame.identity(), owner)
            else:
                self.warn(d, f"{d.type} in a joint's device list: ignored")
        return motors, sensors

    def joint(self, node: Node, frame: Frame, owner: Owner) -> None:
        f = self.fields(node)
        end = f.node_("endPoint")
        motors = [d for d in f.nodes("device") if d.type in MOTORS]
        sensors: list[dict] = []
        if owner.kind == "robot":
            _, sensors = self.joint_devices(node, owner)
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
            self.warn(node, f"{node.type} motor(s) not part of a wheel: listed, not simulated (joints do not move here)")
        if sensors and not (owner.kind == "robot" and node.type == "HingeJoint" and motors):
            self.warn(node, "PositionSensor on a joint without a drive wheel motor: listed, reads no value")
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
        for w in wheels:    # the wheels' encoders measure the drive's wheels
            for entry in w["sensors"]:
                entry["motor"] = w["motor"]


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
