"""Worlds written by Webots R2020b–R2021b, turned as Webots R2022a and later turn them when they open one.

Webots' ``WbNodeUtilities::fixBackwardCompatibility`` (README "Worlds before R2022a") walks the
world's nodes breadth-first, geometries first, and post-multiplies fixed turns onto rotations:

* **B1** a Cylinder, Capsule, Cone, Plane or ElevationGrid turns its Shape's parent (or its own, in a
  boundingObject) by Rx(−π/2), when that parent is a pose holding exactly one node and is no
  TrackWheel's child; otherwise it stays as written and Webots warns;
* **A1** the Viewpoint's orientation turns by Rx(−π/2)·Rz(π/2);
* **A2** a Camera, Lidar or Radar turns by Rx(−π/2)·Rz(π/2), a Pen by Rx(−π/2), an Emitter,
  Receiver, Connector or TouchSensor by Rx(−π/2)·Rz(−π/2); its children and boundingObject that are
  poses take the inverse turn (they stay where they were), the others move into a new pose holding it;
  a boundingObject Group's poses take it until its first other node (geometries first), which, in a new
  pose, replaces the Group.

* **C** (once the PROTO is found, in ``proto.instantiate``) an instance of a PROTO Webots ships whose
  base node is a pose turns by Rx(−π/2)·Rz(π/2).

The same walk converts, in a world of any version, the body of each instance of a PROTO file written up
to R2021b (``turn_proto_body``, from ``proto.instantiate``), as Webots' ``WbConcreteNodeFactory`` does.

What depends on Webots' unstable sort or on a PROTO's body (a PROTO held by a turned device, a Track, a
turned device which holds another turned device under a node that is no pose or more than 16 nodes in its
children and boundingObject Group; in an old PROTO's body, a node an instance's field gives that a rule would change, an old PROTO
inside it, a geometry at its root) is refused in one line rather than guessed."""

from __future__ import annotations

import math
from typing import Any

from sensorium.server.world.proto.interface import BASE_NODES
from sensorium.server.world.wbt.parser import Node, WbtSyntaxError

Matrix = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]

_GEOMETRIES = frozenset({"Cylinder", "Capsule", "Cone", "Plane", "ElevationGrid"})
# Webots' WbGeometry (the sort's first weight)
_ALL_GEOMETRIES = _GEOMETRIES | {"Box", "Sphere", "IndexedFaceSet", "IndexedLineSet", "PointSet", "Mesh"}
_SOLID_DEVICES = frozenset("""Accelerometer Altimeter Camera Compass Connector Display DistanceSensor Emitter GPS
Gyro InertialUnit LED Lidar LightSensor Microphone Pen Radar Radio RangeFinder Receiver Speaker TouchSensor Track
VacuumGripper""".split())
# Webots' WbPose and what derives from it (Transform, every Solid, the solid devices)
_POSES = frozenset({"Pose", "Transform", "Solid", "Robot", "Charger", "Fluid", "TrackWheel"}) | _SOLID_DEVICES


def _euler(rx: float, ry: float, rz: float) -> Matrix:
    """Webots' ``WbMatrix3(rx, ry, rz)``: Rx·Ry·Rz."""
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    return ((cy * cz, -cy * sz, sy),
            (cz * sx * sy + cx * sz, cx * cz - sx * sy * sz, -cy * sx),
            (-cx * cz * sy + sx * sz, cz * sx + cx * sy * sz, cx * cy))


_B1 = _euler(-math.pi / 2, 0.0, 0.0)
_A_CAMERA = _euler(-math.pi / 2, 0.0, math.pi / 2)
_A_EMITTER = _euler(-math.pi / 2, 0.0, -math.pi / 2)
_A2_TURNS = {"Camera": _A_CAMERA, "Lidar": _A_CAMERA, "Radar": _A_CAMERA, "Pen": _B1,
             "Emitter": _A_EMITTER, "Receiver": _A_EMITTER, "Connector": _A_EMITTER, "TouchSensor": _A_EMITTER}


def _mul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _transposed(a: Matrix) -> Matrix:
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _apply(a: Matrix, v: tuple[float, ...]) -> tuple[float, float, float]:
    return (a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2], a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
            a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2])


def _matrix(rotation: Any) -> Matrix:
    """An axis-angle ``x y z angle`` (absent: none) as a matrix."""
    if not (isinstance(rotation, tuple) and len(rotation) == 4):
        return ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    x, y, z, angle = (float(v) for v in rotation)
    n = math.sqrt(x * x + y * y + z * z)
    if n == 0.0:
        return ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    x, y, z = x / n, y / n, z / n
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return ((t * x * x + c, t * x * y - s * z, t * x * z + s * y),
            (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
            (t * x * z - s * y, t * y * z + s * x, t * z * z + c))


def _flushed(v: tuple[float, ...]) -> tuple[float, ...]:
    """Products of cos(pi/2) (6e-17) under 1e-30, which world files may not hold (limits), taken as 0."""
    return tuple(0.0 if abs(x) < 1e-30 else x for x in v)


def _axis_angle(m: Matrix) -> tuple[float, ...]:
    """A rotation matrix as axis-angle (angle in [0, π]; the identity as 0 0 1 0, Webots' default)."""
    angle = math.acos(max(-1.0, min(1.0, (m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0)))
    x, y, z = m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-9:
        if angle < 1e-6:
            return (0.0, 0.0, 1.0, 0.0)
        # a half turn: the axis from the diagonal of (m + I) / 2 = a·aᵀ
        d = [max(0.0, (m[i][i] + 1.0) / 2.0) for i in range(3)]
        i = max(range(3), key=lambda k: d[k])
        axis = [0.0, 0.0, 0.0]
        axis[i] = math.sqrt(d[i])
        for j in range(3):
            if j != i:
                axis[j] = (m[i][j] + m[j][i]) / 4.0 / axis[i]
        return _flushed((axis[0], axis[1], axis[2], angle))
    return _flushed((x / n, y / n, z / n, angle))


def _subnodes(node: Node) -> list[tuple[str, int, Node]]:
    """A node's nodes in its SFNode and MFNode fields: (field, index in a list or -1, node)."""
    out: list[tuple[str, int, Node]] = []
    for name, value in node.fields.items():
        if isinstance(value, Node):
            out.append((name, -1, value))
        elif isinstance(value, list):
            out += [(name, i, v) for i, v in enumerate(value) if isinstance(v, Node)]
    return out


class _NotBase:
    """Every node type but Webots' base nodes (PROTO instances), for ``_contains``."""

    def __contains__(self, name: object) -> bool:
        return name not in BASE_NODES


_NOT_BASE = _NotBase()


def _contains(node: Node, types: frozenset[str] | _NotBase) -> Node | None:
    stack, seen = [node], set()
    while stack:
        n = stack.pop()
        if id(n) in seen:
            continue
        seen.add(id(n))
        if n.type in types:
            return n
        stack += [c for _, _, c in _subnodes(n)]
    return None


class _Turner:
    def __init__(self, version: str, source: str, proto: str | None = None, foreign: frozenset[int] = frozenset()):
        self.version = version
        self.source = source
        # an old PROTO's body (``proto`` its name): the nodes its instance's parameters hold (``foreign``), which
        # Webots walks twice (the parameter and its copy in the body), are refused if a rule would touch them
        self.proto = proto
        self.foreign = foreign
        self.root: Node | None = None
        self.warnings: list[str] = []
        self.done: set[tuple[str, int]] = set()    # (rule, id(node)): a node USEd twice is one node here, two copies in Webots
        self.turned = 0
        self.uses: set[tuple[int, str, int]] = set()  # (id(parent), field, index) of each USE
        self.protos: list[Node] = []                   # the PROTO instances the walk met (rule C)

    def refuse(self, node: Node, why: str) -> WbtSyntaxError:
        if self.proto is not None:
            return WbtSyntaxError(node.source or self.source, node.line, node.col,
                                  f"{node.type} in PROTO {self.proto} (written for Webots {self.version}, whose body "
                                  f"Webots converts at each instance): {why}, so it is not converted here (port the "
                                  "PROTO to R2022a's z-up axes)")
        return WbtSyntaxError(node.source or self.source, node.line, node.col,
                              f"{node.type} in a Webots {self.version} world: {why}, so this world is not converted "
                              "here (open and save it in Webots R2022a or later)")

    def touch(self, node: Node) -> None:
        """A node a rule changes: one a parameter of the PROTO's instance holds is refused."""
        if id(node) in self.foreign:
            raise self.refuse(node, "it comes from a field of the instance, whose node Webots converts twice (the "
                                    "field's and its copy in the body, in an order not settled here)")

    def post_turn(self, node: Node, key: str, turn: Matrix) -> None:
        if (key, id(node)) in self.done:
            return
        self.touch(node)
        self.done.add((key, id(node)))
        field = "orientation" if node.type == "Viewpoint" else "rotation"
        node.fields[field] = _axis_angle(_mul(_matrix(node.fields.get(field)), turn))
        self.turned += 1

    def run(self, roots: list[Node]) -> None:
        # Webots' walk: breadth-first over every copy (a USE is a copy there), each with its parent
        occurrences: list[tuple[Node, Node | None, Node | None, int]] = []  # (node, parent, grandparent, weight)
        queue: list[tuple[Node, Node | None, Node | None]] = [(n, None, None) for n in roots]
        self.preorder_use(roots)
        while queue:
            node, parent, grand = queue.pop(0)
            if node.type not in BASE_NODES:
                # rule C, once the PROTO is found (proto.instantiate: legacy_proto); Webots' walk stops here
                if all(p is not node for p in self.protos):
                    self.protos.append(node)
                continue
            if node.type == "Track":
                raise self.refuse(node, "Webots' turn of a Track's wheels depends on its sort order")
            weight = 3 if node.type in _GEOMETRIES else 1
            occurrences.append((node, parent, grand, weight))
            queue += [(c, node, parent) for _, _, c in _subnodes(node)]
        # stable: Webots' std::sort keeps the walk's order for up to 16 nodes; what else its order decides is refused
        occurrences.sort(key=lambda o: -o[3])
        for node, parent, grand, _ in occurrences:
            if node.type in _GEOMETRIES:
                self.geometry(node, parent, grand)
            elif node.type == "Viewpoint":
                self.post_turn(node, "A1", _A_CAMERA)
            elif node.type in _A2_TURNS:
                self.device(node)

    def preorder_use(self, roots: list[Node]) -> None:
        """Mark which list entries are USEs (a node met again in file order), for Webots' sort weight 2."""
        seen: set[int] = set()
        stack: list[tuple[Node, int, str, int]] = [(n, 0, "", -1) for n in reversed(roots)]
        while stack:
            n, parent, name, i = stack.pop()
            if id(n) in seen:
                self.uses.add((parent, name, i))
                continue
            seen.add(id(n))
            stack += [(c, id(n), f, j) for f, j, c in reversed(_subnodes(n))]

    def geometry(self, node: Node, parent: Node | None, grand: Node | None) -> None:
        self.touch(node)
        holder, above = (parent, grand) if parent is not None and parent.type == "Shape" else (node, parent)
        if self.proto is not None and above is None:
            raise self.refuse(node, "Webots turns the node holding the instance (outside the PROTO's body) for it")
        if holder is None or above is None or above.type not in _POSES or len(_subnodes(above)) != 1:
            self.warnings.append(f"{node.source or self.source}:{node.line}:{node.col}: {node.type}: Webots' "
                                 "conversion to R2022a's z-up axes leaves it as written (its Shape's parent is no "
                                 "Transform or Solid holding it alone): it lies along z, not y, as in Webots")
            return
        self.post_turn(above, "B1", _B1)

    def device(self, node: Node) -> None:
        if ("A2", id(node)) in self.done:
            return
        self.touch(node)
        turn = _A2_TURNS[node.type]
        back = _transposed(turn)
        bounding = node.fields.get("boundingObject")
        # a Group boundingObject (Webots: a Group that is no pose) gives its nodes instead of itself
        group = bounding if isinstance(bounding, Node) and bounding.type in ("Group", "Billboard") else None
        held = [c for c in group.fields.get("children", []) if isinstance(c, Node)] \
            if group is not None and isinstance(group.fields.get("children"), list) else []
        kids = [c for c in node.fields.get("children", []) if isinstance(c, Node)] \
            if isinstance(node.fields.get("children"), list) else []
        for c in [*kids, *held, *([bounding] if isinstance(bounding, Node) and group is None else [])]:
            if c.type not in BASE_NODES:
                raise self.refuse(c, f"a PROTO instance held by a turned {node.type}: whether Webots turns it back "
                                     "depends on its base node, which is not known yet here")
            inside = _contains(c, _NOT_BASE)
            if inside is not None and c.type not in _POSES:
                raise self.refuse(inside, f"a PROTO instance inside a {c.type} of a turned {node.type}, which Webots "
                                          "copies and deletes before it turns its PROTOs")
            if c.type not in _POSES:
                inner = _contains(c, frozenset(_A2_TURNS) | {"Viewpoint", "Track"})
                if inner is not None:
                    raise self.refuse(inner, f"it is inside a {c.type} of a turned {node.type}: whether Webots turns "
                                             "it depends on its sort order")
        if node is self.root:
            # Webots turns no device that is the instance itself (``candidate != node``), only what it holds
            self.done.add(("A2", id(node)))
        else:
            self.post_turn(node, "A2", turn)
        # Webots' order: USEs first, then the others, then DEFs (each wrapped node goes to index 0)
        entries = list(enumerate(kids))
        entries.sort(key=lambda e: -(2 if (id(node), "children", e[0]) in self.uses else 0 if e[1].def_name else 1))
        wrapped: list[Node] = []
        for _, c in entries:
            if c.type in _POSES:
                self.pre_turn(c, back)
            else:
                wrapped.insert(0, self.wrapper(c, back, node))
        if wrapped:
            node.fields["children"] = [*wrapped, *(c for c in kids if c.type in _POSES)]
        if group is not None:
            # Webots' sorted order (geometries, USEs, others, DEFs: a stable insertion sort up to 16 nodes): poses
            # turned back inside the Group until the first other node, which, in a new Pose turning it back,
            # replaces the whole Group; the Group's nodes after it are no longer the device's and stay as they are
            if len(kids) + len(held) > 16:
                raise self.refuse(group, f"a turned {node.type}'s children and its boundingObject Group hold more "
                                         "than 16 nodes, whose order Webots' unstable sort decides")
            order = list(enumerate(held))
            order.sort(key=lambda e: -(3 if e[1].type in _ALL_GEOMETRIES else 2 if (id(group), "children", e[0])
                                       in self.uses else 0 if e[1].def_name else 1))
            for _, c in order:
                if c.type in _POSES:
                    self.pre_turn(c, back)
                else:
                    node.fields["boundingObject"] = self.wrapper(c, back, node)
                    break
        elif isinstance(bounding, Node):
            if bounding.type in _POSES:
                self.pre_turn(bounding, back)
            else:
                node.fields["boundingObject"] = self.wrapper(bounding, back, node)

    def pre_turn(self, node: Node, back: Matrix) -> None:
        if ("pre", id(node)) in self.done:
            return
        self.touch(node)
        self.done.add(("pre", id(node)))
        node.fields["rotation"] = _axis_angle(_mul(back, _matrix(node.fields.get("rotation"))))
        t = node.fields.get("translation")
        if isinstance(t, tuple) and len(t) == 3:
            node.fields["translation"] = _flushed(_apply(back, t))
        self.turned += 1

    def wrapper(self, child: Node, back: Matrix, device: Node) -> Node:
        self.touch(child)
        self.turned += 1
        return Node("Transform", {"rotation": _axis_angle(back), "children": [child]}, child.line, child.col,
                    source=child.source or device.source)


def turn_legacy(roots: list[Node], version: str, source: str) -> tuple[list[str], list[Node]]:
    """Turn an R2020b–R2021b world's nodes (in place) as Webots R2022a+ does on opening it: the warnings
    to report (the first saying it was converted), and the PROTO instances its walk met, which rule C
    turns once their PROTO is found (:func:`turn_proto_instance`)."""
    turner = _Turner(version, source)
    turner.run(roots)
    return [f"{source}:1:1: Webots {version} world: converted as Webots R2022a and later convert it when "
            f"they open it ({turner.turned} node(s) turned, {len(turner.protos)} PROTO instance(s) met; Webots "
            "warns that parts may end up upside down)", *turner.warnings], turner.protos


def turn_proto_instance(node: Node, pose: bool | None = None) -> None:
    """Rule C on an instance of a PROTO Webots ships: a pose (``pose`` None: judged by the node's type,
    an expanded instance's base node) turns by Rx(-pi/2)·Rz(pi/2), Webots' PROTOs turned to z-up in
    R2022a turned back to the world's y-up; another stays."""
    if node.type in _POSES if pose is None else pose:
        node.fields["rotation"] = _axis_angle(_mul(_matrix(node.fields.get("rotation")), _A_CAMERA))


def turn_proto_body(root: Node, proto: str, version: str, source: str,
                    foreign: frozenset[int]) -> tuple[int, list[str], list[Node]]:
    """Webots' conversion of the body of an instance of a PROTO file written up to R2021b
    (``WbConcreteNodeFactory`` calls ``fixBackwardCompatibility`` on each instance it creates, in a world of
    any version): the same walk and rules from the instance's root, in place on ``root`` (a copy of the body
    with the instance's values); ``foreign``: the ids of the nodes those values hold. The device that is the
    instance itself is not turned (its children are). The number of nodes turned, the warnings, and the PROTO
    instances the body holds, which the caller turns by rule C (one Webots ships) or refuses (an old one:
    Webots converts it at its own creation and again here)."""
    turner = _Turner(version, source, proto, foreign)
    turner.root = root
    turner.run([root])
    return turner.turned, turner.warnings, turner.protos
