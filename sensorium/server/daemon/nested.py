"""The Supervisor's nested nodes: what is inside the robots and top-level solids (sans-IO).

A robot's nodes are its world entry's ``nodes`` (the ``.wbt`` import keeps its Solids, devices,
Poses, Transforms, Groups, Slots and joints, schemas.world.NestedNode), or one node per device of
its device list for a robot written without them (a YAML world); a top-level solid's are its ``children`` solids at any depth
and the Poses, Transforms and Groups inside them (``poses``: numbered after the lights, :func:`_number_poses`; the
solids, shapes and lights they hold are their children, in file order by ``seq``).
Both hold their Shapes too, numbered after every other nested node (:func:`_shape_nodes`; their
fields: appearance.py), then the lights a .wbt world writes in them (``LightNode``: an LED's too; their fields:
supervisor.py, on the scene's ``carried_light_slots``). They are
numbered once per simulation, in scene order (robots, then solids, each depth first), from
:data:`FIRST_ID` on: the top-level nodes' ids (robots, solids, lights, the other top-level nodes,
imports) are never shifted by them. The nodes inside a solid a Supervisor imported, or one a PROTO field set
built again, follow as one segment each (:func:`add_solid`: its solids, then its shapes), numbered from the
next id when the Supervisor first looks; :func:`drop` lets a removed or rebuilt solid's go (their ids read as
removed, never given again). A nested node is found by DEF (first in scene order, as
Webots' DEF dictionary) or by a dotted path ``A.B.C`` (each name after the first a direct child's
DEF, Webots' ``getNodeFromDEF``), and by device (``getFromDevice``). A PROTO instance's body nodes are
found by their DEF in that instance's scope (``getFromProtoDef``: :func:`inner_def`, from the import's
``inner_defs``), never by ``getFromDef``.

Its world pose is its owner's pose now (the robot as it drives, the solid as a Supervisor set it)
composed with the node's frame in the owner as the world loaded, moved by the joints it is past: a
node inside a moving joint's end point (the end point Solid, what that Solid holds, a device riding
the joint) is where the joint's link has put it (sim/joints.py ``Links``: the joints' displacements
composed outward), read when a Supervisor asks, never computed otherwise. Its fields are read-only
here (but a joint's parameters' ``position``: supervisor.py): ``translation``/``rotation`` (in its parent's frame: an end point's follow its joint, as
Webots' HingeJoint/SliderJoint set them), ``name`` (Solids and devices), ``children``, and a
joint's ``endPoint`` and ``device`` fields (``end_point``, ``joint_devices``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.daemon import appearance
from sensorium.server.sim.joints import Links
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import pose_from_model

FIRST_ID = 1 << 24
"""The first nested node's id (above any top-level node's: those count from 1)."""

NOT_POSES = frozenset({"RotationalMotor", "LinearMotor", "PositionSensor", "Brake"})
"""Devices Webots does not derive from Pose (no position): a joint's motors and sensors."""

MOVING_JOINTS = frozenset({"HingeJoint", "SliderJoint"})
"""The joints whose ``jointParameters`` hold their motor's position here (a Hinge2Joint's and a
BallJoint's end points move too, on their axes' chain: :func:`_end_point_motors`)."""

CHAINS = {"Hinge2Joint": ("device2", "device"), "BallJoint": ("device3", "device2", "device")}
"""A multi-axis joint's axis fields, innermost first: its end point rides on the innermost motorised
axis (the import turns such a joint into a chain of hinges, each riding on the one before)."""

MOTORS = frozenset({"RotationalMotor", "LinearMotor"})

JOINT_DEVICES = {"HingeJoint": ("device",), "SliderJoint": ("device",), "Hinge2Joint": ("device", "device2"),
                 "BallJoint": ("device", "device2", "device3")}
"""Each joint type's MFNode device fields (Webots'): with its ``endPoint`` (SFNode), how a
Supervisor walks down a robot's tree past its joints."""

HAS_CHILDREN = frozenset({"Solid", "Pose", "Transform", "Group"})
"""Node types with a ``children`` field besides devices that are Solids (Robot, top-level Solid: supervisor.py)."""


@dataclass(frozen=True, slots=True)
class Nested:
    id: int
    type: str             # Webots' base type
    proto: str            # "" for a base node
    def_name: str
    name: str             # a Solid's or device's name ("" for a Pose, Group, joint)
    parent: int           # the parent's node id (a nested node's, or the robot's / top-level solid's)
    field: str            # the parent's field holding it: children, endPoint, device, device2, device3
    local: Pose | None    # in the owner's frame (None: no Pose node)
    own: Pose | None      # in its parent's frame (its translation and rotation fields)
    device: str           # the robot's device it is ("" if none)
    owner: int            # the top-level robot's or solid's node id
    owner_kind: str       # "Robot" | "Solid"
    owner_key: str        # the robot's or solid's name
    joint: str = ""       # the robot's joint motor whose link carries it (the innermost moving joint it is past)
    frame: int = -1       # the id of the nested node whose frame its ``own`` is in (-1: the owner's)
    motor: str = ""       # a joint's JointParameters node: the joint motor whose position it holds
    interface: tuple = () # a PROTO instance's interface (wm.ProtoLevel each: supervisor.py serves its fields)
    order: float = 0.0    # its place among its parent's children (file order: Shapes between the others)
    shape: Any = None     # a Shape or a node inside it: its appearance.ShapeRef (appearance.py serves its fields)
    mass: wm.Mass | None = None   # a Solid's or device's Physics (supervisor.center_of_mass)
    at: tuple[int, ...] = ()      # (line, column) where its owner's file writes it (() none: a PROTO body's, or a node
                                  # in its parent's SF field, found there: export.py)
    made: tuple[int, ...] = ()    # (line, column) where the PROTO body that made it writes it (export.py)
    light: int = -1               # a light: its index among its robot's or top-level solid's lights (the scene's
                                  # ``carried_light_slots``); -1: no light
    scale: tuple[float, ...] | None = None   # a Transform's scale as written (None: 1 1 1)
    path: tuple[int, ...] = ()    # a top-level solid's nested Solid: its place among each parent's ``children`` from the
                                  # top one down (wm.Solid.children indices): the key that names its model (contact points)


@dataclass(slots=True)
class Table:
    nodes: tuple[Nested, ...]                   # the world's, numbered once (:func:`build`)
    by_owner: dict[int, tuple[Nested, ...]]     # owner id -> its nodes, depth first
    by_parent: dict[int, tuple[Nested, ...]]    # parent id -> its direct subnodes
    bare_joints: frozenset[int] = frozenset()   # motorised joints without jointParameters (NULL)
    inner: dict[int, dict[str, int | str]] | None = None   # PROTO instance id -> DEF of its body -> node id, or why
                                                # it is no node here (getFromProtoDef: :func:`inner_defs`)
    added: dict[int, Nested] = dataclasses.field(default_factory=dict)  # the nodes of imported and rebuilt solids now there
    forgotten: set[int] = dataclasses.field(default_factory=set)        # world nodes whose solid was built again (removed)
    removed_shapes: dict[int, Nested] = dataclasses.field(default_factory=dict)  # Shapes a Supervisor removed, and
                                                # the nodes inside them (export leaves them out)
    segments: dict[int, str] = dataclasses.field(default_factory=dict)  # owner id -> its solid's name, for those in ``added``
    end: int = FIRST_ID                         # the next id to give (ids are never reused)
    set_own: dict[int, Pose] = dataclasses.field(default_factory=dict)  # a solid's Pose or Transform a Supervisor
                                                # set: its translation and rotation now (:func:`own_pose`)
    imports_seen: int = 0                       # how many of the simulation's imports were looked at

    def get(self, node_id: int) -> Nested | None:
        """The node of that id: a world node (one a rebuild forgot too: :attr:`forgotten`), or an imported or
        rebuilt solid's while that solid is there; None otherwise (below :attr:`end`: a removed one)."""
        k = node_id - FIRST_ID
        return self.nodes[k] if 0 <= k < len(self.nodes) else self.added.get(node_id)


def robot_entries(robot: Any) -> list[wm.NestedNode]:
    """A robot's nodes: its world entry's, else one per device of its device list (a drive's wheel
    motors too), at the device's pose."""
    model = robot.model
    if model.nodes:
        return list(model.nodes)
    poses = {d.name: d.pose for d in model.devices}
    return [wm.NestedNode(type=e.type, name=e.name, device=e.name,
                          pose=None if e.type in NOT_POSES else poses.get(e.name, wm.Pose()))
            for e in robot.device_list]


def _own(local: Pose | None, above: Pose | None) -> Pose | None:
    """A node's pose in its parent's frame from both in the owner's frame (None: the owner's)."""
    if local is None:
        return None
    return local if above is None else above.inverse().compose(local)


def _first_motors(entries: list[wm.NestedNode]) -> dict[int, str]:
    """A joint entry's index -> its first motor's device name (Webots' rotationalMotor/linearMotor)."""
    motor: dict[int, str] = {}
    for e in entries:
        if e.parent >= 0 and e.field == "device" and e.type in MOTORS and e.parent not in motor:
            motor[e.parent] = e.device or ""
    return motor


def _end_point_motors(entries: list[wm.NestedNode]) -> dict[int, str]:
    """A joint entry's index -> the motor its end point rides on: a HingeJoint's or SliderJoint's
    first motor, a Hinge2Joint's or BallJoint's innermost motorised axis's (:data:`CHAINS`)."""
    motor = _first_motors(entries)
    axes: dict[int, dict[str, str]] = {}
    for e in entries:
        if e.parent >= 0 and e.type in MOTORS and entries[e.parent].type in CHAINS:
            axes.setdefault(e.parent, {}).setdefault(e.field, e.device or "")
    for k, found in axes.items():
        motor[k] = next(found[f] for f in CHAINS[entries[k].type] if f in found)
    return motor


def _riding(robot: Any, entries: list[wm.NestedNode]) -> list[str]:
    """Each entry's joint (the motor of the innermost joint whose end point holds it that the
    simulation moves, "" for none): a device's is its ``on_joint``, where the simulation moves it;
    any other node's is its parent's, or, in a joint's ``endPoint``, the motor it rides on
    (:func:`_end_point_motors`) when it is one of the robot's joint motors (a wheel's motor is the
    drive's: what its end point holds rides with what the wheel rides on, as the import's ``on_joint``)."""
    on = {d.name: d.on_joint or "" for d in robot.model.devices}
    moved = set(robot.joints)
    motor = _end_point_motors(entries)
    out: list[str] = []
    for e in entries:
        if e.device and e.device in on:
            joint = on[e.device]
        elif e.parent < 0:
            joint = ""
        else:
            joint = out[e.parent]
            if e.field == "endPoint" and motor.get(e.parent, "") in moved:
                joint = motor[e.parent]
        out.append(joint)
    return out


def _joint_parameters(sim: Any, robots: list[str], out: list[Nested]) -> tuple[list[Nested], frozenset[int]]:
    """The JointParameters nodes of the robots' motorised HingeJoints and SliderJoints whose world
    file gives one (numbered after every other nested node: the others' ids never move), each
    holding its joint's position; and the ids of those joints whose file gives none (Webots' NULL)."""
    added: list[Nested] = []
    bare: set[int] = set()
    first = 0
    for i, name in enumerate(robots):
        robot = sim.robots[name]
        entries = robot_entries(robot)
        motors = _first_motors(entries)
        for k, e in enumerate(entries):
            motor = motors.get(k, "")
            if e.type not in MOVING_JOINTS or motor not in robot.motors:
                continue
            if not e.joint_parameters:
                bare.add(FIRST_ID + first + k)
                continue
            kind = "HingeJointParameters" if e.type == "HingeJoint" else "JointParameters"
            added.append(Nested(FIRST_ID + len(out) + len(added), kind, "", e.joint_parameters_def or "", "",
                                FIRST_ID + first + k,
                                "jointParameters", None, None, "", i + 1, "Robot", name, motor=motor))
        first += len(entries)
    return added, frozenset(bare)


Holder = tuple[Any, int, int, str, str]
"""A shape to number and where it is: (its model, its parent's id, its owner's id, "Robot" | "Solid", owner key)."""


SolidIds = dict[tuple[int, tuple[int, ...]], int]
"""(owner id, :attr:`Nested.path`) -> the nested solid's node id, as :func:`_solid_nodes` numbers them."""


PoseIds = dict[tuple[int, int], int]
"""(the id of the solid holding it, its index in that solid's ``poses``) -> a Pose's or Group's placeholder id (below
-1) until :func:`_number_poses` numbers them after every other node."""


def _pose_parent(holder: int, index: int, pose_ids: PoseIds) -> int:
    """The parent id of a node of solid ``holder`` held by its ``index``-th Pose or Group (-1: the solid)."""
    return holder if index < 0 else pose_ids[holder, index]


def _solid_holders(s: wm.Solid, holder: int, owner: int, key: str, solid_ids: SolidIds,
                   path: tuple[int, ...] = ()) -> list[Holder]:
    """A top-level solid's shapes (``holder``: its id), then those of the solids inside it, depth first."""
    out: list[Holder] = [(shape, holder, owner, "Solid", key)
                         for shape in ([s] if s.geometry is not None else []) + list(s.shapes)]
    for k, child in enumerate(s.children):
        out += _solid_holders(child, solid_ids[owner, (*path, k)], owner, key, solid_ids, (*path, k))
    return out


def _shape_nodes(sim: Any, holders: list[Holder], first: int, starts: dict[int, int],
                 shape_tags: list[tuple[int, wm.InnerDef, int]], pose_ids: PoseIds | None = None) -> list[Nested]:
    """The Shape nodes of ``holders`` (appearance.py), each followed by the nodes inside it, numbered from id
    ``first``. A robot's shape sits under the node its world entry names (``ShapeNode.parent``: ``starts``
    gives the id of each robot's first entry), a solid's under the solid holding it. A DEF'd appearance,
    material or texture is one node for the shapes among ``holders`` that USE it (its peers: a setter changes
    them all), and so is a mesh the ``.wbt`` import split around its robot's devices: one Shape (its first
    piece's, ``ShapeNode.piece`` on the others) whose nodes' changes reach every piece. ``shape_tags`` gets the PROTO-body DEFs of the shapes and their nodes: (owner id, InnerDef,
    the node's id)."""
    scene = sim.scene
    index = {id(scene.loaded_model(k)): k for k in range(len(scene.shapes))}
    loaded = getattr(sim, "loaded", None)
    wbt = str(getattr(loaded, "source", "")).lower().endswith(".wbt")
    shared: dict[tuple[str, int], list[int]] = {}     # (role, the node's number) -> the shapes holding it
    for shape, *_ in holders:
        held, k = getattr(shape, "node", None), index.get(id(shape))
        if held is not None and k is not None:
            for role, number in (("appearance", held.appearance_key), ("material", held.material_key),
                                 ("texture", held.texture_key)):
                if number >= 0:
                    shared.setdefault((role, number), []).append(k)
    pieces: dict[int, list[int]] = {}     # a split mesh's first piece -> all its pieces (one Shape node)
    first_piece = -1
    for shape, *_ in holders:
        k = index.get(id(shape))
        if k is None:
            continue
        held = getattr(shape, "node", None)
        if held is not None and held.piece and first_piece >= 0:
            pieces[first_piece].append(k)
        else:
            first_piece = k
            pieces[k] = [k]
    added: list[Nested] = []
    inner_tags: list[tuple[int, wm.InnerDef, int]] = []     # (owner, tag, the id of the node it names)

    def add(shape: Any, parent: int, owner: int, kind: str, key: str) -> None:
        k = index.get(id(shape))
        if k is None or k not in pieces or not appearance.served(shape, wbt):
            return              # (a further piece of a split mesh is its first piece's node)
        whole = tuple(pieces[k])
        node = getattr(shape, "node", None)
        if node is not None and kind == "Robot" and node.parent >= 0 and owner in starts:
            parent = starts[owner] + node.parent
        elif node is not None and kind == "Solid" and pose_ids is not None:
            parent = _pose_parent(parent, node.parent, pose_ids)
        order = float("inf") if node is None else node.after + 0.5 if node.seq is None else float(node.seq)
        me = first + len(added)
        added.append(Nested(me, "Shape", "", (node.def_name if node else None) or "", "", parent, "children", None,
                            None, "", owner, kind, key, order=order,
                            shape=appearance.ShapeRef(k, node, "Shape", "Shape", whole),
                            at=tuple(node.written_at or ()) if node is not None else (),
                            made=tuple(node.made_at or ()) if node is not None else ()))
        above = {"appearance": me, "geometry": me}
        ids = {"": me}
        for role, type_, def_name, field in appearance.inside(shape, k):
            nid = first + len(added)
            proto, face = ((node.appearance_proto or "", tuple(node.appearance_interface))
                           if node is not None and role == "appearance" else ("", ()))
            number = -1 if node is None else node.appearance_key if role == "appearance" else \
                node.material_key if role == "material" else node.texture_key if role == "texture" else -1
            peers = tuple(sorted(set(shared.get((role, number), ())).union(whole)))
            added.append(Nested(nid, type_, proto, def_name, "", above[role if role in above else "appearance"], field,
                                None, None, "", owner, kind, key, interface=face,
                                shape=appearance.ShapeRef(k, node, role, type_, peers)))
            if role == "appearance":
                above["appearance"] = nid
            ids[role] = nid
        for tag in (node.inner_defs if node is not None else ()):
            if tag.role in ids:
                inner_tags.append((owner, tag, ids[tag.role]))

    for holder in holders:
        add(*holder)
    shape_tags.extend(inner_tags)
    return added


def _light_node(node_id: int, lt: Any, parent: int, owner: int, kind: str, key: str, light: int,
                tags: list[tuple[int, wm.InnerDef, int | str]]) -> Nested:
    """Light ``lt`` (its ``LightNode``) of a robot or top-level solid (node ``owner``, ``kind`` "Robot" or
    "Solid", ``key`` its name) as node ``node_id`` under node ``parent``, the ``light``-th of its owner's
    lights (the scene's ``carried_light_slots``); ``tags`` gets its PROTO-body DEFs."""
    order = lt.node.after + 0.5 if lt.node.seq is None else float(lt.node.seq)
    made = Nested(node_id, lt.type, "", lt.def_name or "", "", parent, "children", None, None, "", owner, kind, key,
                  order=order, light=light, at=tuple(lt.node.written_at or ()),
                  made=tuple(lt.node.made_at or ()))
    tags.extend((owner, t, node_id) for t in lt.node.inner_defs)
    return made


def _robot_light_nodes(robot: Any, name: str, owner: int, start: int | None, first: int,
                       tags: list[tuple[int, wm.InnerDef, int | str]]) -> list[Nested]:
    """The lights of a robot (node ``owner``) that are nodes (``LightNode``: a .wbt robot's, its LEDs' too),
    numbered from ``first``; ``start``: the id of its first world entry (their parents' ids count from it);
    ``tags`` gets their PROTO-body DEFs."""
    out: list[Nested] = []
    model = robot.model
    lights = list(model.lights) + [lt for d in model.devices if isinstance(d, wm.LED) for lt in d.lights]
    for k, lt in enumerate(lights):       # its own, then its LEDs' (scene.robot_led_lights' order)
        if lt.node is None:
            continue
        parent = owner if lt.node.parent < 0 or start is None else start + lt.node.parent
        out.append(_light_node(first + len(out), lt, parent, owner, "Robot", name, k, tags))
    return out


def _solid_light_nodes(solid: wm.Solid, owner: int, key: str, solid_ids: SolidIds, first: int,
                       tags: list[tuple[int, wm.InnerDef, int | str]], pose_ids: PoseIds) -> list[Nested]:
    """The lights of top-level solid ``solid`` (node ``owner``) and of the solids inside it that are nodes
    (``LightNode``: a .wbt solid's), numbered from ``first``, each under the solid holding it; their indices
    among the solid's lights follow scene.solid_lights (its own, then its children's, depth first); ``tags``
    gets their PROTO-body DEFs."""
    out: list[Nested] = []
    index = 0

    def walk(s: wm.Solid, holder: int, path: tuple[int, ...]) -> None:
        nonlocal index
        for lt in s.lights:
            if lt.node is not None:
                parent = _pose_parent(holder, lt.node.parent, pose_ids)
                out.append(_light_node(first + len(out), lt, parent, owner, "Solid", key, index, tags))
            index += 1
        for k, child in enumerate(s.children):
            walk(child, solid_ids[owner, (*path, k)], (*path, k))

    walk(solid, owner, ())
    return out


def _solid_nodes(solid: wm.Solid, owner: int, key: str, first: int, out: list[Nested], solid_ids: SolidIds,
                 tags: list[tuple[int, wm.InnerDef, int | str]], serials: dict[int, dict[int, int]],
                 posed: list[Nested], pose_ids: PoseIds) -> None:
    """The solids inside top-level solid ``solid`` (node ``owner``, named ``key``) at any depth, appended to
    ``out`` depth first, numbered from ``first`` on (``first + len(out)``), each with its :attr:`Nested.path`;
    ``solid_ids`` gets each one's id by (owner, path), ``tags`` the PROTO-body DEFs, ``serials`` the PROTO
    instances by number."""

    def walk(s: wm.Solid, parent: int, at: Pose | None, path: tuple[int, ...]) -> None:
        frames = _pose_nodes(s, parent, at, owner, key, posed, pose_ids, tags)
        for k, child in enumerate(s.children):
            placed = pose_from_model(child.pose)       # in its parent solid's frame
            own = _own(placed, frames[child.in_pose][0] if child.in_pose >= 0 else None)
            local = placed if at is None else at.compose(placed)
            node = Nested(first + len(out), "Solid", "", child.def_name or "", child.name,
                          _pose_parent(parent, child.in_pose, pose_ids), "children",
                          local, own, "", owner, "Solid", key, order=float(k if child.seq is None else child.seq),
                          frame=frames[child.in_pose][1] if child.in_pose >= 0 else -1, mass=child.mass,
                          at=tuple(child.written_at or ()), made=tuple(child.made_at or ()), path=(*path, k))
            out.append(node)
            solid_ids[owner, node.path] = node.id
            if child.proto_scope is not None:
                serials.setdefault(owner, {})[child.proto_scope] = node.id
            tags.extend((owner, t, node.id) for t in child.inner_defs)
            walk(child, node.id, local, node.path)

    walk(solid, owner, None, ())
    tags.extend((owner, t, t.why) for t in solid.inner_defs if t.why)


def _pose_nodes(s: wm.Solid, holder: int, at: Pose | None, owner: int, key: str, posed: list[Nested],
                pose_ids: PoseIds, tags: list[tuple[int, wm.InnerDef, int | str]]) -> list[tuple[Pose | None, int]]:
    """The Poses, Transforms and Groups of solid ``s`` (node ``holder``, at ``at`` in its top-level solid's frame;
    None: it is that solid) appended to ``posed`` with placeholder ids (``pose_ids``); returns each one's frame:
    (its nearest Pose's pose in ``s``'s frame (None: ``s``'s own), that Pose's id (-1: the solid's))."""
    frames: list[tuple[Pose | None, int]] = []
    for i, p in enumerate(s.poses):
        me = -2 - len(posed)
        pose_ids[holder, i] = me
        above, above_id = frames[p.parent] if p.parent >= 0 else (None, -1)
        placed = None if p.pose is None else pose_from_model(p.pose)
        local = None if placed is None else placed if at is None else at.compose(placed)
        posed.append(Nested(me, p.type, "", p.def_name or "", "", _pose_parent(holder, p.parent, pose_ids),
                            "children", local, _own(placed, above), "", owner, "Solid", key, frame=above_id,
                            order=float(p.seq), at=tuple(p.written_at or ()), made=tuple(p.made_at or ()),
                            scale=p.scale))
        tags.extend((owner, t, me) for t in p.inner_defs)
        frames.append((placed, me) if placed is not None else (above, above_id))
    return frames


def _number_poses(posed: list[Nested], first: int, out: list[Nested],
                  tags: list[tuple[int, wm.InnerDef, int | str]]) -> list[Nested]:
    """The Poses and Groups inside solids numbered from ``first`` on, after every other nested node (no other id
    moves); the parents, frames and PROTO-body DEF targets in ``out`` and ``tags`` naming their placeholder ids
    made theirs. Returns the numbered nodes, ``out`` changed in place."""
    if not posed:
        return []

    def real(node_id: int) -> int:
        return first + (-2 - node_id) if node_id < -1 else node_id

    for k, n in enumerate(out):
        if n.parent < -1 or n.frame < -1:
            out[k] = dataclasses.replace(n, parent=real(n.parent), frame=real(n.frame))
    for k, (owner, tag, target) in enumerate(tags):
        if isinstance(target, int) and target < -1:
            tags[k] = (owner, tag, real(target))
    return [dataclasses.replace(n, id=real(n.id), parent=real(n.parent), frame=real(n.frame)) for n in posed]


def _index(nodes: list[Nested], by_owner: dict[int, tuple[Nested, ...]],
           by_parent: dict[int, tuple[Nested, ...]]) -> None:
    """``nodes`` into the tables by owner and by parent (after what they hold)."""
    owners: dict[int, list[Nested]] = {}
    parents: dict[int, list[Nested]] = {}
    for n in nodes:
        owners.setdefault(n.owner, []).append(n)
        parents.setdefault(n.parent, []).append(n)
    for k, v in owners.items():
        by_owner[k] = by_owner.get(k, ()) + tuple(v)
    for k, v in parents.items():
        by_parent[k] = by_parent.get(k, ()) + tuple(v)


def build(sim: Any, loaded_solids: int) -> Table:
    out: list[Nested] = []
    robots = list(sim.robots)
    tags: list[tuple[int, wm.InnerDef, int | str]] = []     # (owner, tag, the node it names or why it is none)
    firsts: dict[int, int] = {}            # a robot's id -> the id of its first entry (InnerDef.scope 0)
    counts: dict[int, int] = {}            # a robot's id -> how many entries it has
    serials: dict[int, dict[int, int]] = {}     # a top-level solid's id -> its PROTO instances' ids by number
    for i, name in enumerate(robots):
        owner = i + 1
        entries = robot_entries(sim.robots[name])
        joints = _riding(sim.robots[name], entries)
        first = FIRST_ID + len(out)
        firsts[owner] = first
        counts[owner] = len(entries)
        tags.extend((owner, t, t.why) for t in sim.robots[name].model.inner_defs)
        tags.extend((owner, t, first + k) for k, e in enumerate(entries) for t in e.inner_defs)
        frames: list[Pose | None] = []       # each entry's nearest Pose frame in the robot (None: the robot's)
        framed: list[int] = []               # its id (-1: the robot's)
        for k, e in enumerate(entries):
            local = None if e.pose is None else pose_from_model(e.pose)
            above = None if e.parent < 0 else frames[e.parent]
            above_id = -1 if e.parent < 0 else framed[e.parent]
            frames.append(local if local is not None else above)
            framed.append(first + k if local is not None else above_id)
            out.append(Nested(first + k, e.type, e.proto or "", e.def_name or "", e.name or "",
                              owner if e.parent < 0 else first + e.parent, e.field, local, _own(local, above),
                              e.device or "", owner, "Robot", name, joints[k], above_id,
                              interface=tuple(e.interface), order=float(k), mass=e.mass,
                              at=tuple(e.written_at or ()), made=tuple(e.made_at or ()), scale=e.scale))
    solid_ids: SolidIds = {}
    posed: list[Nested] = []
    pose_ids: PoseIds = {}
    for j in range(loaded_solids):
        _solid_nodes(sim.world.solids[j], len(robots) + 1 + j, sim.scene.solid_names[j], FIRST_ID, out, solid_ids,
                     tags, serials, posed, pose_ids)
    parameters, bare = _joint_parameters(sim, robots, out)
    out += parameters
    starts: dict[int, int] = {}       # a robot's node id -> the id of its first world entry
    for n in out:
        if n.owner_kind == "Robot" and n.field != "jointParameters":
            starts.setdefault(n.owner, n.id)
    holders: list[Holder] = []
    for i, name in enumerate(robots):
        model = sim.robots[name].model
        holders += [(shape, i + 1, i + 1, "Robot", name)
                    for shape in ([model.body] if model.body is not None else []) + list(model.shapes)]
    for j in range(loaded_solids):
        owner = len(robots) + 1 + j
        holders += _solid_holders(sim.world.solids[j], owner, owner, sim.scene.solid_names[j], solid_ids)
    shape_tags: list[tuple[int, wm.InnerDef, int]] = []
    out += _shape_nodes(sim, holders, FIRST_ID + len(out), starts, shape_tags, pose_ids)  # after all others: no other id moves
    tags.extend(shape_tags)
    for i, name in enumerate(robots):          # the lights, after the shapes: no shape's id moves
        out += _robot_light_nodes(sim.robots[name], name, i + 1, starts.get(i + 1), FIRST_ID + len(out), tags)
    for j in range(loaded_solids):
        out += _solid_light_nodes(sim.world.solids[j], len(robots) + 1 + j, sim.scene.solid_names[j], solid_ids,
                                  FIRST_ID + len(out), tags, pose_ids)
    out += _number_poses(posed, FIRST_ID + len(out), out, tags)      # the solids' Poses and Groups, after the lights
    inner: dict[int, dict[str, int | str]] = {}
    for owner, tag, target in tags:
        if owner in firsts:                # a robot: the instance's entry (a world file's scope past them: none)
            instance = owner if tag.scope < 0 else firsts[owner] + tag.scope if tag.scope < counts[owner] else None
        else:                              # a top-level solid: the nested solid of that number
            instance = owner if tag.scope < 0 else serials.get(owner, {}).get(tag.scope)
        if instance is not None:
            inner.setdefault(instance, {}).setdefault(tag.name, target)
    by_owner: dict[int, tuple[Nested, ...]] = {}
    by_parent: dict[int, tuple[Nested, ...]] = {}
    _index(out, by_owner, by_parent)
    return Table(tuple(out), by_owner, by_parent, bare, inner, end=FIRST_ID + len(out))


def add_solid(sim: Any, table: Table, owner: int, key: str, solid: wm.Solid) -> None:
    """The nodes inside top-level solid ``solid`` (node ``owner``, named ``key``: an imported solid, or one a
    PROTO field set built again) join ``table`` as a world file's solid's would (its solids, then its shapes
    and their nodes, with their PROTO-body DEFs), numbered from ``table.end`` on: new ids, never a removed
    node's. :func:`drop` takes them out when the solid goes."""
    out: list[Nested] = []
    solid_ids: SolidIds = {}
    tags: list[tuple[int, wm.InnerDef, int | str]] = []
    serials: dict[int, dict[int, int]] = {}
    posed: list[Nested] = []
    pose_ids: PoseIds = {}
    _solid_nodes(solid, owner, key, table.end, out, solid_ids, tags, serials, posed, pose_ids)
    shape_tags: list[tuple[int, wm.InnerDef, int]] = []
    out += _shape_nodes(sim, _solid_holders(solid, owner, owner, key, solid_ids), table.end + len(out), {},
                        shape_tags, pose_ids)
    out += _solid_light_nodes(solid, owner, key, solid_ids, table.end + len(out), tags, pose_ids)
    tags.extend(shape_tags)
    out += _number_poses(posed, table.end + len(out), out, tags)
    inner = table.inner if table.inner is not None else {}
    for _, tag, target in tags:
        instance = owner if tag.scope < 0 else serials.get(owner, {}).get(tag.scope)
        if instance is not None:
            inner.setdefault(instance, {}).setdefault(tag.name, target)
    table.inner = inner
    table.added.update((n.id, n) for n in out)
    _index(out, table.by_owner, table.by_parent)
    table.segments[owner] = key
    table.end += len(out)


def drop(table: Table, owner: int) -> None:
    """The nodes inside top-level node ``owner`` leave the tree (it was removed, or built again): no walk, DEF
    or getFromProtoDef finds them; a world node keeps its entry (:attr:`Table.forgotten`: it reads as removed),
    an imported or rebuilt solid's is let go (its id reads as removed: below ``end``, in no table)."""
    for n in table.by_owner.pop(owner, ()):
        if table.added.pop(n.id, None) is None:
            table.forgotten.add(n.id)
        table.by_parent.pop(n.id, None)
        if table.inner is not None:
            table.inner.pop(n.id, None)
    table.by_parent.pop(owner, None)
    if table.inner is not None:
        table.inner.pop(owner, None)
    table.segments.pop(owner, None)
    for node_id in [k for k, n in table.removed_shapes.items() if n.owner == owner]:
        del table.removed_shapes[node_id]


def renew(sim: Any, table: Table, owner: int, key: str, solid: wm.Solid, kept: int) -> None:
    """The nodes inside top-level solid ``owner`` (named ``key``) built again as ``solid``, the same tree with other
    frames (a Supervisor set a Pose's fields inside it): each keeps its id (a Supervisor's handles stay valid, as
    in Webots), its place and frame now ``solid``'s, its shape the new body's; node ``kept`` (the Pose set) keeps
    its loaded ``own`` (export.py compares it with :attr:`Table.set_own`). Nothing inside it was removed (the
    caller checks): the new nodes come in the order of the old ones."""
    old = table.by_owner.get(owner, ())
    new, state = _made_again(sim, table, owner, key, solid)
    if len(new) != len(old) or any(a.type != b.type for a, b in zip(new, old)):
        raise AssertionError(f"solid {key!r} built again into another tree")
    ids = {n.id: o.id for n, o in zip(new, old)}

    def real(node_id: int) -> int:
        return ids.get(node_id, node_id)

    renewed = [dataclasses.replace(n, id=real(n.id), parent=real(n.parent), frame=real(n.frame),
                                   own=o.own if o.id == kept else n.own) for n, o in zip(new, old)]
    _put_back(table, owner, new, renewed, ids, state, 0)


def reframe(table: Table, owner: int, solid: wm.Solid, changed: Collection[int], kept: int) -> None:
    """:func:`renew` where top-level solid ``owner``'s model ``solid`` differs from the one its nodes were made of
    only by the frames of its ``poses`` at indices ``changed`` (a Supervisor's set moved only shapes: no node comes
    or goes): those Poses' nodes take the ``local`` and ``own`` renew gives them (node ``kept``, the Pose set, its
    loaded ``own``), every other record as it is."""
    mine = {n.at: n for n in table.by_owner.get(owner, ()) if n.type in ("Pose", "Transform") and n.at}
    placed: dict[int, Pose | None] = {}

    def frame(i: int) -> Pose | None:            # a Pose's nearest Pose's frame in the solid's (None: the solid's)
        if i < 0:
            return None
        if i not in placed:
            p = solid.poses[i]
            placed[i] = frame(p.parent) if p.pose is None else pose_from_model(p.pose)
        return placed[i]

    new: dict[int, Nested] = {}
    for i in changed:
        p = solid.poses[i]
        old = mine.get(tuple(p.written_at or ()))
        if old is None or p.pose is None:
            raise AssertionError(f"no node for Pose {i} of solid node {owner}")
        local = frame(i)
        own = old.own if old.id == kept else _own(local, frame(p.parent))
        new[old.id] = dataclasses.replace(old, local=local, own=own)
    if not new:
        return
    first = [k - FIRST_ID for k in new if 0 <= k - FIRST_ID < len(table.nodes)]
    if first:
        nodes = list(table.nodes)
        for k in first:
            nodes[k] = new[k + FIRST_ID]
        table.nodes = tuple(nodes)
    table.added.update((k, n) for k, n in new.items() if k in table.added)
    table.by_owner[owner] = tuple(new.get(n.id, n) for n in table.by_owner[owner])
    for parent in {n.parent for n in new.values()}:
        table.by_parent[parent] = tuple(new.get(n.id, n) for n in table.by_parent.get(parent, ()))


def regrow(sim: Any, table: Table, owner: int, key: str, solid: wm.Solid, gone: frozenset[int] = frozenset(),
           fresh: Any = lambda n: False) -> list[int]:
    """The nodes inside top-level solid ``owner`` (named ``key``) built again as ``solid``, a tree that differs from
    the old one by subtrees a Supervisor imported (``fresh`` names each new one's top nodes) or removed (``gone``:
    the old ids that leave): every other node keeps its id, place and loaded ``own`` as :func:`renew` keeps them;
    the new ones take ids from ``table.end`` on (never a removed node's), the ones that left read as removed.
    Returns the new nodes' ids, in the new tree's order."""
    old = [n for n in table.by_owner.get(owner, ()) if n.id not in gone]
    new, state = _made_again(sim, table, owner, key, solid)
    start = state[0]
    added = {n.id for n in new if fresh(n)}
    grown = True
    while grown:                        # what the new nodes hold is new too
        more = {n.id for n in new if n.parent in added} - added
        added |= more
        grown = bool(more)
    kept = [n for n in new if n.id not in added]
    if len(kept) != len(old) or any(a.type != b.type for a, b in zip(kept, old)):
        raise AssertionError(f"solid {key!r} built again into another tree")
    ids = {n.id: o.id for n, o in zip(kept, old)}
    fresh_ids = [n.id for n in new if n.id in added]
    ids.update((node_id, start + k) for k, node_id in enumerate(fresh_ids))

    def real(node_id: int) -> int:
        return ids.get(node_id, node_id)

    owns = {o.id: o.own for o in old if o.id in table.set_own}
    renewed = [dataclasses.replace(n, id=real(n.id), parent=real(n.parent), frame=real(n.frame),
                                   own=owns.get(real(n.id), n.own)) for n in new]
    for node_id in gone:
        table.set_own.pop(node_id, None)
    _put_back(table, owner, new, renewed, ids, state, len(fresh_ids))
    return [real(n) for n in fresh_ids]


def _made_again(sim: Any, table: Table, owner: int, key: str, solid: wm.Solid) -> tuple[tuple[Nested, ...], tuple]:
    """Top-level solid ``owner``'s nodes made again from ``solid`` (:func:`add_solid`, under new numbers), and the
    table's state before (its end, forgotten ids and whether the solid had a segment) for :func:`_put_back`."""
    state = (table.end, set(table.forgotten), table.segments.get(owner))
    drop(table, owner)
    add_solid(sim, table, owner, key, solid)
    return table.by_owner.pop(owner, ()), state


def _put_back(table: Table, owner: int, new: Sequence[Nested], renewed: list[Nested], ids: dict[int, int],
              state: tuple, fresh: int) -> None:
    """The ``renewed`` nodes (``new`` under the ids they keep: ``ids``, made number -> id) in the table in place
    of the ones :func:`_made_again` made; ``fresh`` new ids taken from the table's old end on."""
    start, forgotten, segment = state
    for n in new:
        table.added.pop(n.id, None)
        table.by_parent.pop(n.id, None)
    table.by_parent.pop(owner, None)
    if table.inner is not None:           # (popped first: a new node's id may be another's number in add_solid)
        moved = {instance: table.inner.pop(instance) for instance in [k for k in table.inner if k in ids or k == owner]}
        for instance, defs in moved.items():
            table.inner[ids.get(instance, instance)] = {k: ids.get(v, v) if isinstance(v, int) else v
                                                        for k, v in defs.items()}
    nodes = list(table.nodes)
    for n in renewed:
        k = n.id - FIRST_ID
        if 0 <= k < len(nodes):
            nodes[k] = n
        else:
            table.added[n.id] = n
    table.nodes = tuple(nodes)
    table.forgotten = forgotten
    table.end = start + fresh
    if segment is None:
        table.segments.pop(owner, None)
    _index(renewed, table.by_owner, table.by_parent)


def drop_shape(table: Table, shape: int) -> None:
    """A Shape node (or a light, or a solid's Pose or Group) a Supervisor removed, with the nodes inside it, leaves the tree: no walk, DEF or
    getFromProtoDef finds them and their ids read as removed (never given again)."""
    gone = {shape}
    todo = [shape]
    while todo:
        for c in table.by_parent.pop(todo.pop(), ()):
            gone.add(c.id)
            todo.append(c.id)
    n = table.get(shape)
    assert n is not None
    for node_id in gone:
        inner = table.get(node_id)
        if inner is not None:
            table.removed_shapes[node_id] = inner
    table.by_parent[n.parent] = tuple(c for c in table.by_parent.get(n.parent, ()) if c.id != shape)
    table.by_owner[n.owner] = tuple(c for c in table.by_owner.get(n.owner, ()) if c.id not in gone)
    for node_id in gone:
        if table.added.pop(node_id, None) is None:
            table.forgotten.add(node_id)
    for defs in (table.inner or {}).values():
        for name in [k for k, v in defs.items() if v in gone]:
            del defs[name]


def inner_def(table: Table, instance: int, name: str) -> int | str | None:
    """getFromProtoDef: the node of PROTO instance ``instance``'s body with DEF ``name`` (its id), why the
    DEF'd node is no node here (a line), or None when the body has no such DEF. The scope is Webots':
    the instance's own body (a derived PROTO's bodies too) with the nodes it holds in its fields; a
    nested PROTO instance's body is its own (the nodes written here that it holds are in)."""
    return (table.inner or {}).get(instance, {}).get(name)


def owner_pose(sim: Any, n: Nested) -> Pose:
    return sim.robots[n.owner_key].pose if n.owner_kind == "Robot" else sim.scene.solid_poses[n.owner_key]


def link(sim: Any, n: Nested) -> Pose | None:
    """Where the joints it is past have moved it now: its joint's link (robot frame, from where the
    world file places it), None when it rides on no joint. The simulation keeps the links of a
    robot on whose joints shapes, lights or devices ride; a robot without them gets its links made
    here, on the first request, and brought up to its joints' positions on each."""
    if not n.joint:
        return None
    robot = sim.robots[n.owner_key]
    links = robot.links
    if links is None:
        spare = getattr(sim, "_nested_links", None)
        if spare is None:
            spare = sim._nested_links = {}
        links = spare.get(n.owner_key)
        if links is None:
            links = spare[n.owner_key] = Links(robot.model, robot.joints)
        links.update()
    pose: Pose = links.poses[n.joint]
    return pose


def robot_frame(sim: Any, n: Nested) -> Pose | None:
    """The node's pose in its owner's frame now (None: no Pose)."""
    if n.local is None:
        return None
    moved = link(sim, n)
    return n.local if moved is None else moved.compose(n.local)


def world_pose(sim: Any, n: Nested) -> Pose | None:
    """The node's pose in the world now; None for a node that is no Pose (Webots: NaN). A node past
    a moving joint is where the joint's link has put it."""
    local = robot_frame(sim, n)
    return None if local is None else owner_pose(sim, n).compose(local)


def own_pose(sim: Any, table: Table, n: Nested) -> Pose | None:
    """Its ``translation``/``rotation`` now (in its parent's frame; None: no Pose): as loaded, but
    for a node a joint moves apart from the frame it is in (a joint's end point), which follow the
    joint as Webots' HingeJoint and SliderJoint set their end point's fields (turned about the
    axis through the anchor by the joint's displacement, slid along the axis)."""
    if n.own is None:
        return None
    if n.id in table.set_own:
        return table.set_own[n.id]
    above = table.get(n.frame)
    if n.joint == (above.joint if above is not None else ""):
        return n.own                        # moved with its frame, or nothing moved
    now = robot_frame(sim, n)
    frame = None if above is None else robot_frame(sim, above)
    assert now is not None
    return now if frame is None else frame.inverse().compose(now)


def velocity(sim: Any, n: Nested) -> list[float]:
    """A node of a driven robot moves with it: v + ω × r (r from the robot's origin), ω; else zeros."""
    drive = sim.robots[n.owner_key].drive if n.owner_kind == "Robot" else None
    if drive is None:
        return [0.0] * 6
    v = drive.velocity()
    pose = world_pose(sim, n)
    if pose is None:
        return [float(x) for x in v]
    r = pose.translation - owner_pose(sim, n).translation
    linear = np.asarray(v[:3], dtype=np.float64) + np.cross(np.asarray(v[3:], dtype=np.float64), r)
    return [float(x) for x in linear] + [float(x) for x in v[3:]]


def joint_parameters(table: Table, joint: int) -> int | None:
    """A motorised joint's ``jointParameters``: its JointParameters node's id, 0 (NULL) when its
    world file gives none; None: no such field here (no joint, or no motor moving it)."""
    if joint in table.bare_joints:
        return 0
    return next((c.id for c in table.by_parent.get(joint, ()) if c.field == "jointParameters"), None)


def joint_position(sim: Any, n: Nested) -> float:
    """A JointParameters node's ``position``: its joint's position now (rad or m; a wheel's angle)."""
    return float(sim.robots[n.owner_key].motors[n.motor].position)


def has_children(n: Nested) -> bool:
    return n.type in HAS_CHILDREN or (n.local is not None and n.type not in ("Pose", "Transform"))


def children(table: Table, parent: int) -> list[int]:
    """The ids of a node's ``children`` (not a joint's end point nor its devices)."""
    return [c.id for c in sorted(table.by_parent.get(parent, ()), key=lambda c: c.order) if c.field == "children"]


def end_point(table: Table, joint: int) -> int:
    """A joint's ``endPoint``: its end point node's id, 0 (NULL) when it has none here."""
    return next((c.id for c in table.by_parent.get(joint, ()) if c.field == "endPoint"), 0)


def joint_devices(table: Table, joint: int, field: str) -> list[int]:
    """The ids of a joint's motors, position sensors and brakes in its ``field`` (``device``, ...)."""
    return [c.id for c in table.by_parent.get(joint, ()) if c.field == field]
