"""The Supervisor (sans-IO): the scene tree Sensorium has, node identity, fields, poses, velocities.

Nodes are what the server simulates at the top of the world: the root (Webots' root Group, id 0,
whose ``children`` lists the others), the robots (ids 1..R in world order), the top-level solids
(R+1..R+S) and the world's top-level lights (then on), and the nodes inside robots and top-level
solids (Solids, devices, Poses, Groups, joints: :mod:`.nested`, ids from ``nested.FIRST_ID``; those of
imported and rebuilt solids too, numbered when first looked at: :func:`_sync_imports`). They
are found by DEF name (``def_name``, set from a ``.wbt`` world's ``DEF``; a dotted path ``A.B`` walks
direct children) or else (top-level nodes) by name. Ids are stable for the life of the server:
a removed solid or light keeps its id, which then answers NULL and is never given to another node; a
top-level solid built again by a PROTO field set keeps its own (Webots keeps a regenerated node's).
Shapes with their appearances and geometries are nested nodes too (:mod:`.appearance`), and so are the
lights a .wbt robot or solid carries (their fields a top-level light's, ``location``/``direction`` in their
parent's frame: :func:`_light`, :func:`_set_carried_light`).

Fields are Webots' names and types (:data:`FIELDS`), values in the parent frame. Setting one field
keeps the others (Webots). A field change applies at once; the next measurement sees it. A nested
node's fields are read-only here, but a joint's parameters' ``position``, a shape's colours,
roughness and transparency (:mod:`.appearance`) and a light's fields. A joint is set with
``set_joint_position``; a node's state is saved and loaded by name (sim/states.py).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
from pydantic import ValidationError

from sensorium.schemas import world as wm
from sensorium.server.daemon import appearance, nested, visuals
from sensorium.server.daemon.mf_items import item_position
from sensorium.server.daemon.roles import MAX_COORDINATE_M, check_pose
from sensorium.server.sim import balance, states, viewshot
from sensorium.server.world.geometry import Pose
from sensorium.server.world.limits import RAISE, custom_data_chars, number_problem
from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion, moved_pose, pose_from_model
from sensorium.server.world.top_nodes import Scenery

T = TypeVar("T")

MODES = ("pause", "realtime", "fast")     # Webots WB_SUPERVISOR_SIMULATION_MODE_PAUSE = 0, REAL_TIME, FAST
LIGHTS = ("PointLight", "SpotLight", "DirectionalLight")


@dataclass(frozen=True, slots=True)
class Node:
    id: int
    type: str          # "Group" (the root) | "Robot" | "Solid" | "PointLight" | "SpotLight" | "DirectionalLight"
    name: str          # a robot's or solid's name; a light's world-file name ("" without one)
    def_name: str      # "" without one
    key: str | int     # the robot's or solid's name, a light's index among the top-level lights, a scenery
                       # node's index (world/top_nodes.py); root: ""
    scenery: bool = False   # a top-level node Sensorium does not simulate (WorldInfo, Viewpoint, Background, ...)
    proto: str = ""         # the PROTO it is an instance of (Webots' getTypeName; ``type`` is its base type)
    nested: bool = False    # inside a robot or top-level solid (nested.py; key: its id)
    interface: tuple = ()   # a PROTO instance's interface: wm.ProtoLevel each, its own PROTO first (getProto)
    visual: bool = False    # an imported Shape or Group, or a node inside one (visuals.py; key: its solid's name)


ROOT = Node(0, "Group", "", "", "")


def _table(sim: Any) -> nested.Table:
    """The nested nodes: the world's, numbered once per simulation, then those of the solids a Supervisor
    imported since (numbered as they are first looked at) and of the solids a PROTO field set built again
    (:func:`_regenerate`); those of a removed solid are let go (:func:`_sync_imports`)."""
    table = getattr(sim, "_supervisor_nested", None)
    if table is None:
        table = nested.build(sim, _loaded_counts(sim)[0] if getattr(sim, "world", None) is not None else 0)
        sim._supervisor_nested = table
    _sync_imports(sim, table)
    return table


def _sync_imports(sim: Any, table: nested.Table) -> None:
    """The nodes inside the imported solids (a Shape or Group imported at the root is visuals.py's) join the
    table, after every node numbered before; those of a solid removed since leave it (memory stays that of
    the solids there now). A solid imported and removed before anyone looked gets no ids."""
    live = sim.scene.solid_poses
    for owner in [o for o, k in table.segments.items() if k not in live]:
        nested.drop(table, owner)
    imported = getattr(sim, "imported", [])
    if table.imports_seen >= len(imported):
        table.imports_seen = min(table.imports_seen, len(imported))
        return
    first = len(_loaded_nodes(sim))                     # the imports' ids follow the loaded nodes' (_all_nodes)
    shown = getattr(sim, "imported_visuals", {})
    for i in range(table.imports_seen, len(imported)):
        kind, key = imported[i]
        if kind == "Solid" and key not in shown and key in live:
            solid = next(s for s in reversed(sim.world.solids) if s.name == key)
            nested.add_solid(sim, table, first + 1 + i, str(key), solid)
    table.imports_seen = len(imported)


def _nested_node(n: nested.Nested) -> Node:
    return Node(n.id, n.type, n.name, n.def_name, n.id, proto=n.proto, nested=True, interface=n.interface)


def _visuals(sim: Any) -> visuals.Store:
    """The imported visual nodes (filled by :func:`_all_nodes` as it numbers the imports)."""
    store = getattr(sim, "_supervisor_visuals", None)
    if store is None:
        store = sim._supervisor_visuals = visuals.Store()
    return store


def _visual_node(v: visuals.VNode) -> Node:
    return Node(v.id, v.type, "", v.def_name, v.key, visual=True)


def _vnode(sim: Any, node: Node) -> visuals.VNode:
    return _visuals(sim).nodes[node.id]


def _nested_of(sim: Any, node: Node) -> nested.Nested:
    found = _table(sim).get(node.id)
    assert found is not None
    return found


def _scenery(sim: Any) -> tuple[Scenery, ...]:
    layout = getattr(sim, "top_level", None)
    return layout.scenery if layout is not None else ()


def _all_nodes(sim: Any) -> list[Node]:
    """Every node the world has had but the root, in id order (the robots, solids and lights it
    loaded with, then its other top-level nodes — WorldInfo, Viewpoint, ... in file order, then
    the ones Webots adds —, then the nodes a Supervisor imported, in import order), removed ones
    included: a node's id is its place here, so it never changes and is never reused."""
    loaded = _loaded_nodes(sim)
    return loaded + _imported_nodes(sim, len(loaded)).every


def _def_of(models: list | None, k: int) -> str:
    return (getattr(models[k], "def_name", None) or "") if models is not None and k < len(models) else ""


def _loaded_nodes(sim: Any) -> list[Node]:
    """The nodes the world loaded with (robots, solids, lights, then the others), in id order."""
    world = getattr(sim, "world", None)
    robots_m = world.robots if world is not None else None
    solids_m = world.solids if world is not None else None
    names = sim.scene.solid_names
    top = sim.scene.top_lights()
    loaded_solids, loaded_lights = _loaded_counts(sim)
    layout = getattr(sim, "top_level", None)
    protos = layout.protos if layout is not None else {}
    faces = getattr(layout, "interfaces", {})
    out = [Node(i + 1, "Robot", name, _def_of(robots_m, i), name, proto=protos.get(("robots", i), ""),
                interface=faces.get(("robots", i), ())) for i, name in enumerate(sim.robots)]
    first = len(out) + 1
    out += [Node(first + j, "Solid", names[j], _def_of(solids_m, j), names[j], proto=protos.get(("solids", j), ""),
                 interface=faces.get(("solids", j), ())) for j in range(loaded_solids)]
    first = len(out) + 1
    out += [Node(first + k, top[k].type, top[k].name or "", _def_of(top, k), k, proto=protos.get(("lights", k), ""),
                 interface=faces.get(("lights", k), ())) for k in range(loaded_lights)]
    first = len(out) + 1
    out += [Node(first + x, s.type, "", s.def_name, x, scenery=True, proto=s.proto, interface=s.interface)
            for x, s in enumerate(_scenery(sim))]
    return out


@dataclass
class _Imported:
    """The nodes a Supervisor imported, made once each (a Supervisor importing and removing for days asks
    for nodes in time bounded by those there now, not by every node the world has had): ``every`` in
    import order (ids), ``live`` those not yet seen removed (a removed node never comes back), the
    import counts by kind; ``stamp``: what they were made from (a solid built again, a light changed)."""

    stamp: tuple
    every: list[Node] = dataclasses.field(default_factory=list)
    live: list[Node] = dataclasses.field(default_factory=list)
    solids: int = 0
    lights: int = 0
    lights_version: int = 0     # the scene's when they were made (an imported light's fields changed)


def _imported_nodes(sim: Any, first: int) -> _Imported:
    """The imported nodes (ids after the ``first`` loaded ones), the new imports numbered on the way."""
    imported = getattr(sim, "imported", [])
    scene = sim.scene
    counters = getattr(sim, "_counters", {})
    store = _visuals(sim)
    stamp = (first, id(store), id(getattr(sim, "world", None)), counters.get("regenerations", 0))
    kept = getattr(sim, "_supervisor_imported", None)
    if kept is None or kept.stamp != stamp or len(kept.every) > len(imported) or \
            (kept.lights and kept.lights_version != scene.lights_version):
        kept = sim._supervisor_imported = _Imported(stamp, lights_version=scene.lights_version)
    if len(kept.every) == len(imported):
        return kept
    world = getattr(sim, "world", None)
    solids_m = world.solids if world is not None else None
    names = scene.solid_names
    top = scene.top_lights()
    imported_protos = getattr(sim, "imported_protos", {})
    imported_faces = getattr(sim, "imported_interfaces", {})
    imported_visuals = getattr(sim, "imported_visuals", {})
    new = imported[len(kept.every):]

    def place(key: str) -> int:          # an imported solid's name is among the last ones
        return next(j for j in range(len(names) - 1, -1, -1) if names[j] == key)

    for kind, key in new:
        node_id = first + len(kept.every) + 1
        proto, face = imported_protos.get(key, ""), imported_faces.get(key, ())
        written = imported_visuals.get(key)
        if written is not None:           # a Shape or Group (visuals.py), held by a solid named key
            store.add(str(key), node_id, written)
            node = Node(node_id, written.type, "", written.def_name or "", key, visual=True)
        elif kind == "Solid":
            node = Node(node_id, "Solid", str(key), _def_of(solids_m, place(key)), key, proto=proto, interface=face)
        else:
            lt = top[int(key)]
            node = Node(node_id, lt.type, lt.name or "", _def_of(top, int(key)), key, proto=proto, interface=face)
        kept.every.append(node)
        kept.live.append(node)
        kept.solids += kind == "Solid"
        kept.lights += kind != "Solid"
    kept.lights_version = scene.lights_version
    return kept


def _removed(sim: Any, node: Node) -> bool:
    if node.scenery:
        return False
    if node.visual:                  # with the solid holding it
        return node.key not in sim.scene.solid_poses
    if node.nested:                  # with its top-level solid, or when that solid was built again
        table = _table(sim)
        n = table.get(node.id)
        return n is None or node.id in table.forgotten or (n.owner_kind == "Solid"
                                                           and n.owner_key not in sim.scene.solid_poses)
    if node.type == "Solid":
        return node.key not in sim.scene.solid_poses
    return node.type in LIGHTS and node.key in sim.scene.removed_lights


def _nodes(sim: Any) -> list[Node]:
    """The nodes in the world now, in id order."""
    loaded = _loaded_nodes(sim)
    kept = _imported_nodes(sim, len(loaded))
    kept.live = [n for n in kept.live if not _removed(sim, n)]     # (removed for good)
    return [n for n in loaded if not _removed(sim, n)] + kept.live


def _loaded_order(sim: Any, nodes: list[Node]) -> list[int]:
    """The ids of the root's children as the world loaded: its top-level nodes in file order
    (world/top_nodes.py); id order without a layout."""
    layout = getattr(sim, "top_level", None)
    if layout is None:
        return [n.id for n in nodes]
    solids, lights = _loaded_counts(sim)
    first = {"robots": 1, "solids": 1 + len(sim.robots)}           # ids as _all_nodes gives them
    first["lights"] = first["solids"] + solids
    first["scenery"] = first["lights"] + lights
    return [first[kind] + index for kind, index in layout.order]


def _loaded_counts(sim: Any) -> tuple[int, int]:
    """How many top-level solids and lights the world loaded with (those now, imported ones left out)."""
    imported = getattr(sim, "imported", [])          # (appended to only: counted once each)
    n, solids, lights = getattr(sim, "_supervisor_counted", (0, 0, 0))
    if n > len(imported):
        n, solids, lights = 0, 0, 0
    for kind, _ in imported[n:]:
        solids += kind == "Solid"
        lights += kind != "Solid"
    if n != len(imported):
        sim._supervisor_counted = (len(imported), solids, lights)
    return len(sim.scene.solid_names) - solids, len(sim.scene.top_lights()) - lights


def root_children(sim: Any) -> list[Node]:
    """The root's ``children`` in their order: the world file's top-level nodes in file order
    (Webots' WorldInfo and Viewpoint added where missing), imported nodes where they were inserted."""
    by_id = {n.id: n for n in _nodes(sim)}
    order = getattr(sim, "root_order", None) or _loaded_order(sim, list(by_id.values()))
    return [by_id[i] for i in order if i in by_id]


def _member_ids(sim: Any, members: tuple[tuple[str, int], ...]) -> list[int]:
    """The ids of a top-level group's members (world/top_nodes.py), removed ones included."""
    solids, _ = _loaded_counts(sim)
    first = {"robots": 1, "solids": 1 + len(sim.robots)}           # ids as _all_nodes gives them
    first["lights"] = first["solids"] + solids
    return [first[kind] + index for kind, index in members]


def _group_members(sim: Any, node: Node) -> list[Node]:
    """A top-level Group's, Pose's or Transform's children (world/top_nodes.py): the robots, solids and
    lights it holds, removed ones left out."""
    if not node.scenery or not _scenery(sim)[int(node.key)].members:
        return []
    by_id = {n.id: n for n in _nodes(sim)}
    return [by_id[i] for i in _member_ids(sim, _scenery(sim)[int(node.key)].members) if i in by_id]


def _group_of(sim: Any, node: Node) -> int:
    """The id of the top-level group holding a top-level node; the root's (0) for one no group holds."""
    if node.scenery or node.nested or node.visual:
        return 0
    layout = getattr(sim, "top_level", None)
    if layout is None or not any(s.members for s in layout.scenery):
        return 0
    first = 1 + len(sim.robots) + sum(_loaded_counts(sim))           # the first scenery node's id
    return next((first + x for x, s in enumerate(layout.scenery) if s.members and node.id in _member_ids(sim, s.members)),
                0)


def _scene_tops(sim: Any) -> list[Node]:
    """The root's children, each group followed by the nodes it holds."""
    return [m for top in root_children(sim) for m in (top, *_group_members(sim, top), *(
        _robot_riders(sim, top) if top.type == "Robot" else ()))]


def _first_def(sim: Any, name: str) -> Node | None:
    """The first node in Webots' scene order (the root's children, each followed by the nodes inside
    it) with DEF ``name``; only that one is made a Node."""
    table = _table(sim)
    for top in _scene_tops(sim):
        if top.def_name == name:
            return top
        if top.visual:
            inner = next((v for v in _visuals(sim).inside(top.id) if v.def_name == name), None)
            if inner is not None:
                return _visual_node(inner)
            continue
        hit = next((n for n in table.by_owner.get(top.id, ()) if n.def_name == name), None)
        if hit is not None:
            return _nested_node(hit)
    return None


def find_node(sim: Any, name: str) -> Node | None:
    """Webots' getFromDef: the first node in scene order whose DEF name is ``name``'s first part, then
    for each further dotted part (``ROBOT.ARM.CAMERA``) the direct child (in any node field) with that
    DEF; for a name without a dot and no DEF: the robot, top-level solid or light of that name."""
    first, *path = name.split(".")
    if path and path[-1] == "":          # "A." is A (Webots reads nothing after the dot)
        path.pop()
    if not first or "" in path:          # a node without a DEF is never found by one
        return None
    found = _first_def(sim, first)
    if found is None and not path:
        found = next((n for n in _nodes(sim) if n.name == name), None)
    table = _table(sim)
    for part in path:
        if found is None:
            return None
        if found.scenery:
            found = next((m for m in _group_members(sim, found) if m.def_name == part), None)
            continue
        if found.visual:
            store = _visuals(sim)
            v = next((v for v in store.nodes.values() if v.parent == found.id and v.def_name == part), None)
            found = None if v is None else _visual_node(v)
            continue
        sub = next((c for c in table.by_parent.get(found.id, ()) if c.def_name == part), None)
        found = None if sub is None else _nested_node(sub)
    return found


def device_node(sim: Any, robot: str, device: str) -> Node | None:
    """Webots' getFromDevice: the node of the calling robot's device of that name."""
    me = robot_node(sim, robot)
    table = _table(sim)
    hit = None if me is None else next((n for n in table.by_owner.get(me.id, ()) if n.device == device), None)
    return None if hit is None else _nested_node(hit)


def robot_node(sim: Any, robot: str) -> Node | None:
    return next((n for n in _nodes(sim) if n.type == "Robot" and n.key == robot), None)


def _known_ids(sim: Any) -> str:
    """The node ids there are, for an error line: the top-level ones, then the nested ones."""
    end = _table(sim).end
    nested_ids = f", nested {nested.FIRST_ID}..{end - 1}" if end > nested.FIRST_ID else ""
    return f"ids 0..{len(_all_nodes(sim))}: 0 the root{nested_ids}"


def node_by_id(sim: Any, node: int) -> Node:
    if node == 0:
        return ROOT
    if node >= visuals.FIRST_ID:
        _all_nodes(sim)                  # (numbers the imports' visual nodes)
        v = _visuals(sim).nodes.get(node)
        if v is None and node < _visuals(sim).next_id:       # (taken out of its field by removeSF)
            raise ValueError(f"node {node} was removed")
        if v is None:
            raise ValueError(f"no node with id {node} ({_known_ids(sim)})")
        found = _visual_node(v)
        if _removed(sim, found):
            raise ValueError(f"node {node} ({found.type}) was removed with the imported node holding it")
        return found
    if node >= nested.FIRST_ID:
        table = _table(sim)
        inner = table.get(node)
        if inner is None and node < table.end:
            raise ValueError(f"node {node} was removed with the imported or rebuilt solid holding it")
        if inner is None:
            raise ValueError(f"no node with id {node} ({_known_ids(sim)})")
        found = _nested_node(inner)
        if _removed(sim, found):
            if node in table.removed_shapes:    # (by itself: remove_node)
                raise ValueError(f"node {node} ({found.type} {found.def_name or found.name!r}) was removed")
            how = " when a PROTO field set built it again" if inner.owner_key in sim.scene.solid_poses else ""
            raise ValueError(f"node {node} ({found.type} {found.name!r}) was removed with {inner.owner_key!r}{how}")
        return found
    nodes = _all_nodes(sim)
    if not 0 <= node <= len(nodes):
        raise ValueError(f"no node with id {node} ({_known_ids(sim)})")
    found = nodes[node - 1]
    if _removed(sim, found):
        raise ValueError(f"node {node} ({found.type} {found.name or found.key!r}) was removed")
    return found


def robot_of_node(sim: Any, node: int) -> str:
    """The name of the robot node ``node`` is (restartController); ValueError for another node."""
    found = node_by_id(sim, node)
    if found.type != "Robot" or found.nested:
        raise ValueError(f"node {node} ({found.type} {found.name!r}) is no robot")
    return str(found.key)


def node_from_id(sim: Any, node: int) -> Node | None:
    """Webots' ``getFromId``: the node, or None (NULL) for an id that is no node."""
    try:
        return node_by_id(sim, node)
    except ValueError:
        return None


def node_ref(sim: Any, node: Node | None) -> dict:
    if node is None:
        return {"node": 0, "type": "", "name": "", "def_name": "", "parent": -1, "proto": ""}
    rider = _rider(sim, node) if node.type == "Solid" else None
    parent = _nested_of(sim, node).parent if node.nested else _vnode(sim, node).parent \
        if node.visual and node.id >= visuals.FIRST_ID else -1 if node.id == 0 else _group_of(sim, node) \
        if rider is None else robot_node(sim, rider[0]).id       # type: ignore[union-attr]
    return {"node": node.id, "type": node.type, "name": node.name, "def_name": node.def_name,
            "parent": parent, "proto": node.proto}


def _pose(sim: Any, node: Node) -> Any:
    return sim.robots[node.key].pose if node.type == "Robot" else sim.scene.solid_poses[node.key]


NO_TURN = 10000 * sys.float_info.epsilon
"""An angle below this is no turn (WbPrecision::DOUBLE_EQUALITY_TOLERANCE, WbRotation's)."""


def matrix_axis_angle(r: np.ndarray) -> list[float]:
    """Rotation matrix → Webots axis-angle (unit axis, angle in [0, pi]); identity → 0 0 1 0, and so
    is a turn by less than ``NO_TURN`` (as WbRotation: rounding, e.g. a joint turned back to where
    the file placed its end point, leaves no axis of noise). Through the unit quaternion, which
    stays accurate near half turns."""
    x, y, z, w = matrix_quaternion(r)             # w >= 0
    n = math.sqrt(x * x + y * y + z * z)
    angle = 2.0 * math.atan2(n, w)
    if n < 1e-300 or angle < NO_TURN:
        return [0.0, 0.0, 1.0, 0.0]
    return [x / n, y / n, z / n, angle]


# ---------------------------------------------------------------------- fields
# per node type: Webots field name -> (Webots field type name, getter(sim, node), setter(sim, node, value) or None)

Getter = Callable[[Any, Node], Any]
Setter = Callable[[Any, Node, Any], None] | None


def _check_pose_value(field: str, value: list[float]) -> None:
    """A ``translation`` or ``rotation`` value a Supervisor sets: finite, within the world's limits, a
    rotation about a non-zero axis (one line each, nothing changed)."""
    if not all(math.isfinite(v) for v in value):
        raise ValueError(f"field {field!r}: values must be finite")
    if field == "translation":
        check_pose(translation=value)
    if field == "rotation" and math.hypot(*value[:3]) == 0.0:
        raise ValueError("rotation axis must not be zero")


def _set_pose(sim: Any, node: Node, field: str, value: list[float]) -> None:
    _check_pose_value(field, value)
    kwargs = {"translation": value} if field == "translation" else {"translation": None, "rotation": value}
    if node.type == "Robot":
        robot = sim.robots[node.key]
        frame = sim.rider_frame(robot) if hasattr(sim, "rider_frame") else None
        if frame is not None:        # a robot riding another: its fields are in its parent's frame (WbPose)
            parent = sim.rider_parent(robot)
            if parent is None:
                sim.set_rider_frame(robot, moved_pose(frame, **kwargs))
            else:
                sim.set_rider_frame(robot, parent.compose(moved_pose(parent.inverse().compose(frame), **kwargs)))
            return
        robot.set_pose(**kwargs)
    else:
        sim.set_solid_pose(node.key, **kwargs)


def _field_pose(sim: Any, node: Node) -> Any:
    """What a robot's or solid's ``translation`` and ``rotation`` fields give: its pose in the world, a robot
    riding another's in its carrier's frame (its parent's, as Webots gives a nested node's fields)."""
    robot = sim.robots[node.key] if node.type == "Robot" and hasattr(sim, "rider_frame") else None
    frame = sim.rider_frame(robot) if robot is not None else None
    if frame is None:
        return _pose(sim, node)
    parent = sim.rider_parent(robot)
    return frame if parent is None else parent.inverse().compose(frame)


_POSE_FIELDS: dict[str, tuple[str, Getter, Setter]] = {
    "translation": ("SFVec3f", lambda sim, n: [float(v) for v in _field_pose(sim, n).translation],
                    lambda sim, n, v: _set_pose(sim, n, "translation", v)),
    "rotation": ("SFRotation", lambda sim, n: matrix_axis_angle(_field_pose(sim, n).rotation),
                 lambda sim, n, v: _set_pose(sim, n, "rotation", v)),
}


def _solid_model(sim: Any, node: Node) -> Any:
    return next(s for s in sim.world.solids if s.name == node.key)


def _carrier(sim: Any, node: Node) -> tuple[str | int, int]:
    """A nested light's robot (its index) or top-level solid (its name) and its index among their lights."""
    n = _nested_of(sim, node)
    return (sim.robots[n.owner_key].index if n.owner_kind == "Robot" else n.owner_key), n.light


def _carried_model(sim: Any, node: Node) -> Any:
    """A nested light's model as the scene holds it (``location``/``direction`` in its owner's frame)."""
    owner, k = _carrier(sim, node)
    return sim.scene.light_model(sim.scene.carried_light_slots(owner)[k])


def _light(sim: Any, node: Node) -> Any:
    """A light's model as its fields read: a nested light's ``location``/``direction`` in its parent's frame."""
    if not node.nested:
        return sim.scene.top_lights()[node.key]
    model = _carried_model(sim, node)
    return model.model_copy(update={a: getattr(model.node, a) for a in ("location", "direction")
                                    if getattr(model.node, a) is not None})


def _set_carried_light(sim: Any, node: Node, attr: str, changed: Any) -> None:
    """A nested light's field set: ``changed`` (its fields as read, :func:`_light`) placed in its owner's
    frame by its parent's (``LightNode.frame``, after its ``linear`` scale), a spot light's light-sensor axis turned by ``LightNode.aim``
    (the .wbt import's rule, sim/scene.py ``sensor_aimed``); the other fields as set."""
    stored = _carried_model(sim, node)
    info = stored.node
    keep = {a: getattr(stored, a) for a in ("location", "direction", "light_sensor_direction") if hasattr(stored, a)}
    placed = changed.model_copy(update=keep)
    if attr in ("location", "direction"):
        value = getattr(changed, attr)
        info = info.model_copy(update={attr: value})
        frame = pose_from_model(info.frame)
        update: dict[str, Any] = {}
        if attr == "location":
            local = np.asarray(value, dtype=np.float64)
            if info.linear is not None:         # under a scaled Transform: scaled first, as the import placed it
                local = np.asarray(info.linear, dtype=np.float64).reshape(3, 3) @ local
            update["location"] = tuple(float(v) for v in frame.apply(local))
        elif changed.type == "SpotLight":        # a directional light's direction is in world axes (Webots)
            update["direction"] = tuple(float(v) for v in frame.apply_dirs(np.asarray(value, dtype=np.float64)))
            if info.aim is not None:
                aim = pose_from_model(info.aim).apply_dirs(np.asarray(value, dtype=np.float64))
                update["light_sensor_direction"] = tuple(float(v) for v in aim)
        else:
            update["direction"] = tuple(float(v) for v in value)
        placed = placed.model_copy(update=update)
    owner, k = _carrier(sim, node)
    sim.scene.set_carried_light(owner, k, placed.model_copy(update={"node": info}))


def _radar_key(sim: Any, node: Node) -> str | int:
    """A robot's or solid's key among the scene's radar targets (robot index, solid name)."""
    return sim.robots[node.key].index if node.type == "Robot" else node.key


def _get_radar_cross_section(sim: Any, node: Node) -> float:
    return float(sim.scene.radar_targets.get(_radar_key(sim, node), 0.0))


def _set_radar_cross_section(sim: Any, node: Node, value: float) -> None:
    """Webots' WbSolid::updateRadarCrossSection: above 0 the node is a radar target (a new one comes
    after the others), 0 it is none; negative values are refused, as in a world file."""
    if value < 0.0:
        raise ValueError(f"field 'radarCrossSection': must be >= 0, got {value}")
    key = _radar_key(sim, node)
    if value > 0.0:
        sim.scene.radar_targets[key] = float(value)
    else:
        sim.scene.radar_targets.pop(key, None)


_RADAR_FIELD: dict[str, tuple[str, Getter, Setter]] = {
    "radarCrossSection": ("SFFloat", _get_radar_cross_section, _set_radar_cross_section)}


def _set_light(attr: str, kind: str) -> Setter:
    def setter(sim: Any, node: Node, value: Any) -> None:
        model = _light(sim, node)
        problem = wm.light_value_problem(attr, value)      # Webots' ranges, as the world file's
        if problem is None:      # the numbers a world file may hold (so that exportString's text imports again)
            numbers = [v for v in (value if isinstance(value, (list, tuple)) else [value])
                       if isinstance(v, (int, float)) and not isinstance(v, bool)]
            problem = next(filter(None, (number_problem(float(v), sim.limits) for v in numbers)), None)
        if problem is not None:
            raise ValueError(f"{kind} {attr}: {problem}")
        if attr == "location" and any(abs(v) > MAX_COORDINATE_M for v in value):   # as every pose a request sets
            raise ValueError(f"{kind} location {value} is outside the world bounds "
                             f"(|coordinate| <= {MAX_COORDINATE_M:g} m)")
        try:
            changed = type(model).model_validate({**model.model_dump(), attr: value})
            if attr == "direction" and kind == "SpotLight":    # the new direction, in world axes, for light
                changed = changed.model_copy(update={"light_sensor_direction": None})   # sensors as for cameras
        except ValidationError as e:
            raise ValueError(f"{kind} {attr}: {e.errors()[0]['msg'].removeprefix('Value error, ')}") from None
        if kind == "SpotLight" and changed.beam_width > changed.cut_off_angle:
            if attr == "beam_width":      # Webots resets it to the cut-off with a warning: refused, as other ranges
                raise ValueError(f"{kind} {attr}: must be <= cut_off_angle ({changed.cut_off_angle}), got {value}")
            changed = changed.model_copy(update={"beam_width": changed.cut_off_angle})   # WbSpotLight: silently
        if kind in ("PointLight", "SpotLight") and changed.ambient_intensity != 0.0 \
                and tuple(changed.attenuation) != (1.0, 0.0, 0.0):
            # checkAmbientAndAttenuationExclusivity: Webots sets the ambient intensity to 0 (a warning); the
            # ambient intensity set itself is refused, as other resets; a new attenuation zeroes it
            if attr == "ambient_intensity":
                raise ValueError(f"{kind} {attr}: must be 0 while attenuation is not 1 0 0 (Webots' rule), "
                                 f"got {value}")
            changed = changed.model_copy(update={"ambient_intensity": 0.0})
        if node.nested:
            _set_carried_light(sim, node, attr, changed)
        else:
            sim.scene.set_top_light(node.key, changed)
    return setter


def _light_fields(kind: str) -> dict[str, tuple[str, Getter, Setter]]:
    fields = {"on": ("SFBool", "on"), "intensity": ("SFFloat", "intensity"), "color": ("SFColor", "color"),
              "ambientIntensity": ("SFFloat", "ambient_intensity"), "castShadows": ("SFBool", "cast_shadows")}
    if kind != "DirectionalLight":
        fields |= {"location": ("SFVec3f", "location"), "attenuation": ("SFVec3f", "attenuation"),
                   "radius": ("SFFloat", "radius")}
    if kind != "PointLight":
        fields["direction"] = ("SFVec3f", "direction")
    if kind == "SpotLight":
        fields |= {"beamWidth": ("SFFloat", "beam_width"), "cutOffAngle": ("SFFloat", "cut_off_angle")}

    def getter(attr: str) -> Getter:
        def get(sim: Any, node: Node) -> Any:
            v = getattr(_light(sim, node), attr)
            return [float(c) for c in v] if isinstance(v, tuple | list) else v
        return get

    return {name: (t, getter(attr), _set_light(attr, kind)) for name, (t, attr) in fields.items()}


def _set_custom_data(sim: Any, node: Node, value: str) -> None:
    """Webots' WbRobot::updateData: the robot's controller reads the new value with getCustomData once
    its next step returns (services.py sends it with that step reply); bounded as the world file's."""
    limit = custom_data_chars(sim.limits)
    if len(value) > limit:
        raise ValueError(f"field 'customData': {len(value)} characters, over the world's limit of {limit} "
                         f"{RAISE}; nothing changed")
    sim.robots[node.key].custom_data = value


def _battery(robot: Any) -> list[float]:
    """A robot's ``battery`` as Webots' field holds it: its present energy first (sim/battery.py), then
    the maximum and recharge speed as loaded; as many values as the world gives."""
    b = robot.battery
    return [b.energy, b.maximum, b.speed][:len(robot.model.battery)]


_BATTERY_ITEMS = ("energy", "maximum", "speed")     # Webots' CURRENT_ENERGY, MAX_ENERGY, ENERGY_UPLOAD_SPEED


def _set_battery_item(sim: Any, node: Node, where: str, op: str, index: Any, value: Any) -> None:
    """Webots' ``setMFFloat`` on a robot's ``battery``: WbRobot reads the field's items live, so a write of the
    energy (0) is what the battery holds now: its sensor reads it at its next sample, the step's drain takes
    from it and powers the robot off at 0 or (a robot off) on again with energy left; the maximum (1) caps
    what a Charger gives, the speed (2) is what it gives. The number of values is the world's (one line)."""
    robot = sim.robots[node.key]
    if op != "set":
        raise ValueError(f"{where}: its values are set here, not inserted or removed (the world gives "
                         f"{len(robot.model.battery)}); nothing changed")
    at = item_position(where, op, index, len(robot.model.battery))
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 <= value < math.inf:
        raise ValueError(f"{where}: item {index} takes a finite number >= 0 ({('J', 'J', 'W')[at]}), got {value!r}; "
                         "nothing changed")
    problem = number_problem(float(value), sim.limits)      # what a world file's battery may hold
    if problem is not None:
        raise ValueError(f"{where}: item {index}: {problem}; nothing changed")
    setattr(robot.battery, _BATTERY_ITEMS[at], float(value))


def _set_cpu_consumption(sim: Any, node: Node, value: float) -> None:
    """Webots' WbRobot reads ``cpuConsumption`` at each step's drain: the next step drains at the new power."""
    if not value >= 0.0:
        raise ValueError(f"field 'cpuConsumption' takes a value >= 0 (W), got {value!r}; nothing changed")
    problem = number_problem(float(value), sim.limits)      # what a world file's cpuConsumption may be
    if problem is not None:
        raise ValueError(f"field 'cpuConsumption': {problem}; nothing changed")
    sim.robots[node.key].battery.cpu = float(value)


def _set_controller(sim: Any, node: Node, value: str) -> None:
    """Webots' WbRobot::updateControllerDir: the value only; services.py ends the running controller and
    `sensorium run`'s launcher starts the named one (a Supervisor's set_field compares before and after)."""
    sim.robots[node.key].controller = value


def _children(sim: Any, node: Node) -> list[int]:
    """A robot's, solid's or nested node's ``children``: the nodes inside it (nested.py); a robot's with the solids
    a Supervisor imported there (:func:`_import_into_robot`) where they were inserted."""
    inside = nested.children(_table(sim), node.id)
    order = getattr(sim, "_robot_child_order", {}).get(node.key) if node.type == "Robot" and not node.nested else None
    if not order:
        return inside
    riding = {n.id for n in _robot_riders(sim, node)}
    return [i for i in order if i in riding or i in inside] + [i for i in inside if i not in order]


FIELDS: dict[str, dict[str, tuple[str, Getter, Setter]]] = {
    "Group": {"children": ("MFNode", lambda sim, n: [m.id for m in root_children(sim)], None)},
    "Robot": {**_POSE_FIELDS,
              "children": ("MFNode", _children, None),
              "name": ("SFString", lambda sim, n: n.name, None),
              "model": ("SFString", lambda sim, n: sim.robots[n.key].model.model, None),
              "customData": ("SFString", lambda sim, n: sim.robots[n.key].custom_data, _set_custom_data),
              "controller": ("SFString", lambda sim, n: sim.robots[n.key].controller, _set_controller),
              "supervisor": ("SFBool", lambda sim, n: bool(sim.robots[n.key].supervisor), None),
              "synchronization": ("SFBool", lambda sim, n: bool(sim.robots[n.key].synchronization), None),
              "battery": ("MFFloat", lambda sim, n: _battery(sim.robots[n.key]), None),
              "cpuConsumption": ("SFFloat", lambda sim, n: sim.robots[n.key].battery.cpu, _set_cpu_consumption),
              **_RADAR_FIELD},
    "Solid": {**_POSE_FIELDS,
              "children": ("MFNode", _children, None),
              "name": ("SFString", lambda sim, n: n.name, None),
              "model": ("SFString", lambda sim, n: _solid_model(sim, n).model, None),
              **_RADAR_FIELD},
    **{kind: _light_fields(kind) for kind in LIGHTS},
}

def _info(attr: str, convert: Callable[[Any], Any] = lambda v: v) -> Getter:
    return lambda sim, n: convert(getattr(sim.world.world_info, attr))


def _written(name: str, default: Any) -> Getter:
    def get(sim: Any, n: Node) -> Any:
        v = _scenery(sim)[int(n.key)].fields.get(name, default)
        return [list(c) if isinstance(c, list | tuple) else c for c in v] if isinstance(v, list | tuple) else v
    return get


SCENERY_FIELDS: dict[str, dict[str, tuple[str, Getter, Setter]]] = {
    # what the world model keeps of WorldInfo (read-only here); a .wbt world without a title: its file name
    "WorldInfo": {"title": ("SFString", _info("name", str), None),
                  "basicTimeStep": ("SFFloat", _info("basic_time_step", float), None),
                  "randomSeed": ("SFInt32", _info("random_seed", int), None),
                  "coordinateSystem": ("SFString", _info("coordinate_system", str), None),
                  "gravity": ("SFFloat", _info("gravity", float), None),
                  "gpsCoordinateSystem": ("SFString", _info("gps_coordinate_system", str), None),
                  "gpsReference": ("SFVec3f", _info("gps_reference", lambda v: [float(c) for c in v]), None),
                  "inkEvaporation": ("SFFloat", _info("ink_evaporation", float), None)},
    # the world file's values (wbt/convert.SCENERY_VALUES), else Webots' defaults (a Viewpoint Webots adds, a
    # YAML world's); read-only here (but moveViewpoint's position: move_viewpoint): no sky to recolour
    "Viewpoint": {"fieldOfView": ("SFFloat", _written("fieldOfView", 0.785398), None),
                  "orientation": ("SFRotation", _written("orientation", [0.0, 0.0, 1.0, 0.0]), None),
                  "position": ("SFVec3f", _written("position", [-10.0, 0.0, 0.0]), None),
                  "near": ("SFFloat", _written("near", 0.05), None),
                  "far": ("SFFloat", _written("far", 0.0), None),
                  "exposure": ("SFFloat", _written("exposure", 1.0), None),
                  "description": ("SFString", _written("description", ""), None),
                  "follow": ("SFString", _written("follow", ""), None),
                  "followType": ("SFString", _written("followType", "Tracking Shot"), None),
                  "followSmoothness": ("SFFloat", _written("followSmoothness", 0.5), None)},
    "Background": {"skyColor": ("MFColor", _written("skyColor", [[0.0, 0.0, 0.0]]), None),
                   "luminosity": ("SFFloat", _written("luminosity", 1.0), None)},
    # a top-level group holding solids (world/top_nodes.py): its children are those nodes (the same ids their
    # DEFs give); its pose is the world file's, read-only (its solids move one by one: setting it moves none)
    "Group": {"children": ("MFNode", lambda sim, n: [m.id for m in _group_members(sim, n)], None)},
    "Pose": {"children": ("MFNode", lambda sim, n: [m.id for m in _group_members(sim, n)], None),
             "translation": ("SFVec3f", _written("translation", [0.0, 0.0, 0.0]), None),
             "rotation": ("SFRotation", _written("rotation", [0.0, 0.0, 1.0, 0.0]), None)},
}
SCENERY_FIELDS["Transform"] = {**SCENERY_FIELDS["Pose"], "scale": ("SFVec3f", _written("scale", [1.0, 1.0, 1.0]), None)}
"""Fields of the top-level nodes Sensorium does not simulate; any other field of theirs (and any
field of Fog, a Transform, ...) answers Webots' "no value"."""


def _own_pose(sim: Any, node: Node) -> Any:
    """A nested node's translation and rotation now (an end point's follow its joint: nested.py)."""
    own = nested.own_pose(sim, _table(sim), _nested_of(sim, node))
    assert own is not None
    return own


def _own_translation(sim: Any, node: Node) -> list[float]:
    """A nested node's translation now; a Pose's inside a top-level solid that no Supervisor set: the value its
    world file or node string writes (its pose in its parent's frame, worked back from the solid's, is that value
    to a rounding: -0.59 read -0.5899999999999999)."""
    from sensorium.server.sim.regenerate import written_fields

    n = _nested_of(sim, node)
    if n.owner_kind == "Solid" and n.type in _SOLID_POSES and n.at and n.id not in _table(sim).set_own:
        written = written_fields(sim, n.owner_key, (n.at[0], n.at[1]), ("translation",))
        if written is not None:
            return [float(v) for v in written["translation"] or (0.0, 0.0, 0.0)]
    return [float(v) for v in _own_pose(sim, node).translation]


_NESTED_POSE: dict[str, tuple[str, Getter, Setter]] = {
    "translation": ("SFVec3f", _own_translation, None),
    "rotation": ("SFRotation", lambda sim, n: matrix_axis_angle(_own_pose(sim, n).rotation), None),
}


def _nested_fields(sim: Any, node: Node) -> dict[str, tuple[str, Getter, Setter]]:
    """A nested node's fields, all read-only here: its pose in its parent's frame, its name, its
    children; a moving joint's ``jointParameters`` and their ``position``."""
    n = _nested_of(sim, node)
    if n.shape is not None:            # a Shape or a node inside it (appearance.py)
        return appearance.fields(n.shape, lambda field: _sf_child(sim, n.id, field))
    if n.light >= 0:                   # a light inside a robot or solid: as a top-level light's
        return FIELDS[n.type]
    out = dict(_NESTED_POSE) if n.own is not None else {}
    if n.own is not None and n.owner_kind == "Solid" and n.type in ("Pose", "Transform") and n.at:
        out = {name: (kind, get, _solid_pose_setter(name)) for name, (kind, get, _) in out.items()}
    if n.type == "Transform":          # as written; set only inside a top-level solid (:func:`_set_solid_scale`)
        out["scale"] = ("SFVec3f", lambda sim, node: [float(v) for v in _nested_of(sim, node).scale or (1.0, 1.0, 1.0)],
                        _set_solid_scale if n.owner_kind == "Solid" and n.at else None)
    if n.name:
        out["name"] = ("SFString", lambda sim, node: node.name, None)
    if nested.has_children(n):
        out["children"] = ("MFNode", _children, None)
    if n.type in nested.JOINT_DEVICES:     # walked down as in Webots: the end point, the devices
        out["endPoint"] = ("SFNode", lambda sim, node: nested.end_point(_table(sim), node.id), None)
        for name in nested.JOINT_DEVICES[n.type]:
            out[name] = ("MFNode", lambda sim, node, name=name: nested.joint_devices(_table(sim), node.id, name), None)
    parameters = nested.joint_parameters(_table(sim), n.id)
    if parameters is not None:        # a motorised joint's (0: NULL), holding its position now
        out["jointParameters"] = ("SFNode", lambda sim, node: parameters, None)
    if n.motor:
        out["position"] = ("SFFloat", lambda sim, node: nested.joint_position(sim, _nested_of(sim, node)),
                           _set_parameter_position)
    return out


_LOADED = {"Pose": ("translation", "rotation"), "Transform": ("translation", "rotation", "scale")}
"""The fields a ``simulationReset`` puts back in a Pose or Transform a Supervisor set inside a top-level solid."""


def _set_solid_scale(sim: Any, node: Node, value: list[float]) -> None:
    """A Transform's ``scale`` inside a top-level solid set (WbTransform): the Shapes it holds are from the next
    measurement what the world file written with that value makes of them, its solid built again through the path a
    PROTO field set takes (sim/regenerate.py ``rebuild_posed``; a zero component is 1, Webots' reset), node ids
    kept; ``simulationReset`` puts the loaded value back. One line and nothing changed for a non-finite value, a
    Transform holding anything but Shapes (a scale there would change which nodes it holds: a Pose under a scaled
    Transform is no node here, a Solid none in Webots) and every solid :func:`_set_solid_pose` refuses."""
    from sensorium.server.sim.imports import ImportRefused
    from sensorium.server.sim.regenerate import rebuild_posed, written_children, written_node, written_value

    if not all(math.isfinite(v) for v in value):
        raise ValueError("field 'scale': values must be finite")
    table = _table(sim)
    n = _nested_of(sim, node)
    key = n.owner_key
    doing = f"field 'scale' of {_what(node)} not set"
    _check_rebuildable(sim, table, n.owner, key, doing, "the new scale")
    at = (n.at[0], n.at[1])
    written = written_node(sim, key, at)
    if written is None:
        raise ValueError(f"{doing}: solid {key!r} was not loaded from a .wbt world file's node kept here (a solid a "
                         "Supervisor imported); nothing changed")
    held = sorted({getattr(c, "type", "") for c in written_children(written)} - {"Shape"})
    if held:
        raise ValueError(f"{doing}: it holds a {held[0]}, and only a Transform holding Shapes alone is scaled again "
                         "here (a scale would change which nodes it holds); nothing changed")
    loaded = {name: written.fields.get(name) for name in _LOADED["Transform"]}
    fields = {"scale": written_value("SFVec3f", [float(v) for v in value])}
    try:
        made = _rebuilt_in_place(sim, key, lambda: rebuild_posed(sim, key, n.owner, at, fields))
    except ImportRefused as exc:
        raise ValueError(f"{doing}: {exc}; nothing changed") from None
    sim.__dict__.setdefault("_posed", {}).setdefault(key, {}).setdefault(at, (n.id, loaded))
    nested.renew(sim, table, n.owner, key, made.model, n.id)


def _solid_pose_setter(field: str) -> Setter:
    return lambda sim, node, value: _set_solid_pose(sim, node, field, value)


def _set_solid_pose(sim: Any, node: Node, field: str, value: list[float]) -> None:
    """A Pose's or Transform's ``translation`` or ``rotation`` inside a top-level solid set (WbPose): what it
    holds (shapes, lights, solids) is from the next measurement where the world file written with that value
    puts it, its solid built again through the path a PROTO field set takes (sim/regenerate.py
    ``rebuild_posed``), or where the set only moves visual shapes, those shapes placed anew (``move_posed``: the
    same readings; ``sim.rebuild_pose_sets`` true always rebuilds, for tests and benchmarks); every node inside
    the solid keeps its id. ``simulationReset`` puts the loaded value
    back (:func:`reset_solid_poses`); its shapes keep the appearances a Supervisor gave them. One line and nothing
    changed for a solid a rebuild would lose more of (a node inside it removed, a light's field set) or a
    Charger's."""
    from sensorium.server.sim.imports import ImportRefused
    from sensorium.server.sim.regenerate import move_posed, rebuild_posed, written_fields, written_value

    _check_pose_value(field, value)
    table = _table(sim)
    n = _nested_of(sim, node)
    key = n.owner_key
    _check_rebuildable(sim, table, n.owner, key, f"field {field!r} of {_what(node)} not set", "the new frame")
    at = (n.at[0], n.at[1])
    loaded = written_fields(sim, key, at, _LOADED[n.type])
    if loaded is None:
        raise ValueError(f"field {field!r} of {_what(node)} not set: solid {key!r} was not loaded from a .wbt "
                         "world file's node kept here (a solid a Supervisor imported); nothing changed")
    own = nested.own_pose(sim, table, n)
    assert own is not None
    was_set = n.id in table.set_own
    kind = "SFVec3f" if field == "translation" else "SFRotation"
    value = _writable(field, value)
    fields = {field: written_value(kind, value)}
    # only shapes moved within the solid: placed anew, the solid not built again (the same readings and records)
    moved = None if getattr(sim, "rebuild_pose_sets", False) else move_posed(sim, key, at, fields)
    if moved is None:
        try:
            made = _rebuilt_in_place(sim, key, lambda: rebuild_posed(sim, key, n.owner, at, fields))
        except ImportRefused as exc:
            raise ValueError(f"field {field!r} of {_what(node)} not set: {exc}; nothing changed") from None
    sim.__dict__.setdefault("_posed", {}).setdefault(key, {}).setdefault(at, (n.id, loaded))
    if moved is None:
        nested.renew(sim, table, n.owner, key, made.model, n.id)
    else:
        nested.reframe(table, n.owner, *moved, n.id)
    translation = np.asarray(value, dtype=np.float64) if field == "translation" else own.translation
    if field != "translation" and not was_set:    # its written translation, not the one worked back to a rounding
        translation = np.asarray(loaded.get("translation") or (0.0, 0.0, 0.0), dtype=np.float64)
    rotation = axis_angle_matrix(value[:3], value[3]) if field == "rotation" else own.rotation
    table.set_own[n.id] = Pose(rotation, translation)


def _check_rebuildable(sim: Any, table: nested.Table, owner: int, key: str, doing: str, with_what: str) -> None:
    """One line (``doing``: what is refused) for a top-level solid a rebuild would lose more of: a node inside it a
    Supervisor removed (but the ones it imported there: :func:`_remove_imported`) or a light's field it set, or a
    Charger's."""
    scene = sim.scene
    if any(m.owner == owner for m in table.removed_shapes.values()) or set(scene.solid_shapes(key)) & \
            scene.removed_shapes or any(k[0] == key for k in scene.changed_carried()):
        raise ValueError(f"{doing}: a Supervisor removed a node or changed a light inside solid {key!r}, which "
                         f"building it again with {with_what} would undo; nothing changed")
    if any(c.solid == key for c in sim.chargers):
        raise ValueError(f"{doing}: solid {key!r} is a Charger's (its glowing shapes stay those it loaded with "
                         "here); nothing changed")


def _rebuilt_in_place(sim: Any, key: str, build: Callable[[], Any]) -> Any:
    """Top-level solid ``key`` built again by ``build`` (it builds it where it was loaded), then put where a
    Supervisor had moved it, its shapes keeping the appearances a Supervisor gave them; returns what it became."""
    scene = sim.scene
    looks = scene.appearance_changes(key)
    places = _shape_places(sim, key)
    now_pose = scene.solid_poses[key]
    built = pose_from_model(next(s for s in reversed(sim.world.solids) if s.name == key).pose)
    moved = not (np.array_equal(now_pose.translation, built.translation)
                 and np.array_equal(now_pose.rotation, built.rotation))
    made = build()
    if moved:                        # built where the solid was loaded, then moved where the Supervisor put it
        sim.place_solid(key, now_pose)
    after = {place: k for k, place in enumerate(_shape_places(sim, key))}
    # (its shapes keep the colours a Supervisor gave them, each found by where it is written: an import or a
    # removal moves the others among the solid's shapes)
    scene.take_appearance_changes(key, {after[places[k]]: v for k, v in looks.items() if places[k] in after})
    return made


def _shape_places(sim: Any, key: str) -> list[tuple]:
    """Each shape of top-level solid ``key``, in its order, by where its file writes it (a split mesh's pieces,
    or shapes written nowhere, by their count among those written at the same place)."""
    out: list[tuple] = []
    seen: dict[tuple, int] = {}
    for shape in sim.scene.solid_shapes(key):
        node = getattr(sim.scene.loaded_model(shape), "node", None)
        at = (tuple(node.written_at or ()), tuple(node.made_at or ())) if node is not None else ((), ())
        seen[at] = seen.get(at, -1) + 1
        out.append((*at, seen[at]))
    return out


def _writable(field: str, value: list[float]) -> list[float]:
    """A Pose's set value as its world file written anew takes it, the same translation or rotation: an axis
    normalized (as Webots keeps it), a component under the loader's 1e-30 written 0 (a robot's or solid's set
    takes either; written as given, the loader refused the solid in a line naming a shape in it), an angle past
    its 1e9 as the angle in [-π, π] of the same sine and cosine."""
    if field == "rotation":
        axis = np.asarray(value[:3], dtype=np.float64)
        axis = axis / np.abs(axis).max()           # (scaled first: an axis of 1e-300's squares to 0)
        axis = axis / np.linalg.norm(axis)
        angle = value[3] if abs(value[3]) <= 1e9 else math.atan2(math.sin(value[3]), math.cos(value[3]))
        value = [*axis.tolist(), angle]
    return [0.0 if abs(v) < 1e-30 else float(v) for v in value]


def reset_solid_poses(sim: Any) -> None:
    """After a ``simulationReset``: the Poses and Transforms a Supervisor set inside top-level solids back at
    their loaded values (WbPose::reset), their solids built again so (node ids kept)."""
    from sensorium.server.sim.regenerate import rebuild_posed

    posed = sim.__dict__.pop("_posed", {})
    if not posed:
        return
    table = _table(sim)
    for key, sets in posed.items():
        if key not in sim.scene.solid_poses or not sets:
            continue
        owner = next(n.owner for n_id, _ in sets.values() for n in [table.get(n_id)] if n is not None)
        # the nodes inside it a Supervisor removed since stay removed (Webots' reset), where building the solid
        # again from its written node brought them back (and the node table no longer matched it)
        gone = {(m.at[0], m.at[1]) for m in table.removed_shapes.values() if m.owner == owner and m.at}
        made = None
        for at, (node_id, loaded) in sets.items():
            table.set_own.pop(node_id, None)
            if at not in gone:       # (a removed Pose's value is seen nowhere: left as set)
                made = rebuild_posed(sim, key, owner, at, loaded, gone)
        if made is not None:
            nested.renew(sim, table, owner, key, made.model, -1)


def _sf_child(sim: Any, parent: int, field: str) -> int:
    """The id of the node in a nested node's SFNode ``field`` (0: NULL)."""
    return next((c.id for c in _table(sim).by_parent.get(parent, ()) if c.field == field), 0)


def _set_parameter_position(sim: Any, node: Node, value: float) -> None:
    """A joint's ``jointParameters.position`` set (WbHingeJoint/WbSliderJoint::updatePosition): the
    joint is there at once, what rides on it with it; its motor keeps its target (Webots sets it only
    before the robot's controller has configured its motors), so a motor holding a position brings
    the joint back."""
    check_joint_position(value)
    n = _nested_of(sim, node)
    robot = sim.robots[n.owner_key]
    motor = robot.motors[n.motor]
    motor.position = float(value)
    sim.joints_moved(robot)


def _visual_fields(sim: Any, node: Node) -> dict[str, tuple[str, Getter, Setter]]:
    """An imported visual node's fields: what the string wrote, Webots' defaults otherwise (visuals.py)."""
    v = _vnode(sim, node)

    def getter(name: str) -> Getter:
        def get(sim: Any, n: Node) -> Any:
            value = v.values[name]
            return [list(x) if isinstance(x, list) else x for x in value] if isinstance(value, list) else value
        return get

    out: dict[str, tuple[str, Getter, Setter]] = {name: (kind, getter(name), None)
                                                  for name, kind in visuals.fields(v).items()}
    ref = _visual_shape(sim, v)
    if ref is not None and v.type in appearance.SETTABLE:      # an area shape's colours: the appearance path
        served = appearance.fields(ref, lambda field: 0)
        for name in appearance.SETTABLE[v.type]:
            if name in served and name in out:
                out[name] = served[name]
    return out


def _visual_shape(sim: Any, v: visuals.VNode) -> appearance.ShapeRef | None:
    """The appearance path's reference for a node of an imported area shape (its scene shape, found as
    the import's solid's shapes in order), None for any other node."""
    if v.shape < 0 or v.role not in ("appearance", "material"):
        return None
    solid = next((s for s in reversed(sim.world.solids) if s.name == v.key), None)
    shapes = [] if solid is None else list(solid.shapes)
    if v.shape >= len(shapes):
        return None
    model = shapes[v.shape]
    node = getattr(model, "node", None)
    k = next((k for k in range(len(sim.scene.shapes)) if sim.scene.loaded_model(k) is model), None)
    holder = v
    store = _visuals(sim)
    while holder.role != "Shape" and holder.parent in store.nodes:
        holder = store.nodes[holder.parent]
    geometry = store.nodes.get(holder.values.get("geometry", 0))
    if node is None or k is None or (v.role == "material" and not node.material) or \
            geometry is None or node.geometry != geometry.type:      # (the converter's order, checked)
        return None
    return appearance.ShapeRef(k, node, v.role, v.type)


def _base_fields(sim: Any, node: Node) -> dict[str, tuple[str, Getter, Setter]]:
    if node.visual and node.id >= visuals.FIRST_ID or node.visual and node.type in visuals.ROOTS:
        return _visual_fields(sim, node)
    if node.nested:
        return _nested_fields(sim, node)
    if node.scenery and node.type in ("Group", "Pose", "Transform") and not _scenery(sim)[int(node.key)].members:
        return {}            # a group of shapes only: a visual node (visuals.py), not served from here
    if node.type == "Solid" and _rider(sim, node) is not None:      # in its robot's frame
        return {**FIELDS["Solid"], **_RIDER_POSE}
    return SCENERY_FIELDS.get(node.type, {}) if node.scenery else FIELDS[node.type]


def _level(node: Node, level: int) -> int:
    """The fields a request names: -1 is the node's own (a PROTO instance's: its PROTO's, 1; else its base
    node's, 0)."""
    return (1 if node.interface else 0) if level < 0 else level


def _interface_fields(sim: Any, node: Node, level: int) -> dict[str, tuple[str, Getter, Setter]]:
    """The interface fields of PROTO ``level`` (1: the instance's own PROTO) of a PROTO instance. A field
    whose value passes through IS unchanged to a base-node field served here reads that field now (a
    robot's ``translation`` as it drives) and, on the instance's own PROTO, sets it as that field does;
    any other field answers the instance's value (or the PROTO's default); setting one builds a top-level
    solid again (:func:`_regenerate`, Webots' regeneration) and is refused on any other node."""
    if not 1 <= level <= len(node.interface):
        raise ValueError(f"{_what(node)} has no PROTO at level {level} (its PROTO chain: "
                         f"{' > '.join(p.name for p in node.interface) or 'none, it is no PROTO instance'})")
    proto = node.interface[level - 1]
    base = _base_fields(sim, node)
    out: dict[str, tuple[str, Getter, Setter]] = {}
    for f in proto.fields:
        through = base.get(f.base) if f.base else None
        if through is not None and through[0] == f.type:
            out[f.name] = (f.type, through[1], through[2] if level == 1 else None)
        else:
            out[f.name] = (f.type, _kept_value(proto.name, f), None)
    return out


class NotKept(ValueError):
    """A PROTO field whose value Sensorium does not keep: get_field answers its type and this line."""


def _kept_value(proto: str, f: Any) -> Getter:
    def get(sim: Any, node: Node) -> Any:
        if f.value is None:
            why = "a node-typed PROTO field is not served here unless it passes straight through IS to the base " \
                  "node's field" if f.type.endswith("Node") else "its value is over 4096 items, not kept here"
            raise NotKept(f"field {f.name!r} ({f.type}) of PROTO {proto} ({_what(node)}): {why}")
        return f.value
    return get


def _fields(sim: Any, node: Node, level: int = -1) -> dict[str, tuple[str, Getter, Setter]]:
    level = _level(node, level)
    return _base_fields(sim, node) if level == 0 else _interface_fields(sim, node, level)


_VECTOR_SIZES = {"SFVec2f": 2, "SFVec3f": 3, "SFColor": 3, "SFRotation": 4}


_JOINT_FIELDS = {"endPoint": frozenset(nested.JOINT_DEVICES), "device": frozenset(nested.JOINT_DEVICES),
                 "jointParameters": frozenset(nested.JOINT_DEVICES),
                 "device2": frozenset({"Hinge2Joint", "BallJoint"}), "jointParameters2": frozenset({"Hinge2Joint", "BallJoint"}),
                 "device3": frozenset({"BallJoint"}), "jointParameters3": frozenset({"BallJoint"})}
_PARAMETERS = frozenset({"HingeJointParameters", "JointParameters", "BallJointParameters"})
_SCENERY = frozenset({"WorldInfo", "Viewpoint", "Background", "Fog", "PointLight", "SpotLight", "DirectionalLight"})
_NO_POSE = frozenset(nested.JOINT_DEVICES) | nested.NOT_POSES | _PARAMETERS | _SCENERY | appearance.TYPES | \
    (visuals.TABLES.keys() - {"Pose", "Transform", "Group"})
_WEBOTS_LACKS = {"children": _NO_POSE, "translation": _NO_POSE | {"Group"}, "rotation": _NO_POSE | {"Group"},
                 "name": frozenset(nested.JOINT_DEVICES) | _PARAMETERS | _SCENERY | {"Pose", "Transform", "Group"}
                 | (appearance.TYPES - {"Appearance", "PBRAppearance"})}


def webots_lacks(node_type: str, field: str) -> bool:
    """Whether Webots' node of that base type has no such field either, for the fields a
    Supervisor probes as it walks a robot's tree (a joint's ``endPoint``/``device``/
    ``jointParameters``, ``children``, the pose, ``name``): libController then answers NULL
    with no message. False when unsure (the clients then say the field is not served here)."""
    if field in _JOINT_FIELDS:
        return node_type not in _JOINT_FIELDS[field]
    return node_type in _WEBOTS_LACKS.get(field, ())


def get_field(sim: Any, node: Node, field: str, level: int = -1) -> dict:
    """``{"type", "value"}``; type '' (and value []) when the node has no such field here, plus
    ``absent: true`` when Webots' node has none either (``webots_lacks``). ``level``: whose fields
    (-1 the node's: a PROTO instance's interface; 0 its base node's; k its k-th PROTO's)."""
    level = _level(node, level)
    entry = _fields(sim, node, level).get(field)
    if entry is None:
        if level > 0:         # a PROTO has no such interface field: Webots' NULL, no line (as libController)
            return {"type": "", "value": [], "absent": True}
        return {"type": "", "value": [], "absent": True} if webots_lacks(node.type, field) else {"type": "", "value": []}
    try:
        return {"type": entry[0], "value": entry[1](sim, node)}
    except NotKept as exc:
        return {"type": entry[0], "value": [], "note": str(exc)}


MAX_HIDDEN = 4096
"""(node, device) pairs a Supervisor may keep hidden at once (setVisibility), Viewpoint included."""
_SEEING = frozenset({"Camera", "Lidar", "RangeFinder"})


def _node_shapes(sim: Any, node: Node) -> frozenset[int]:
    """The scene's shapes of ``node`` and of what is inside it: every shape of a robot or top-level solid
    (the solids inside it too), the Shape nodes at or under a node inside one, every shape for the root."""
    scene = sim.scene
    if node.id == 0:
        return frozenset(range(len(scene.shapes)))
    if node.type == "Robot" and not node.nested:
        return frozenset(scene.target_shapes(sim.robots[node.key].index))
    if node.type == "Solid" and not (node.nested or node.scenery or node.visual):
        return frozenset(scene.target_shapes(node.key))
    if not node.nested:
        return frozenset()
    table = _table(sim)
    out: set[int] = set()
    todo = [_nested_of(sim, node)]
    while todo:
        n = todo.pop()
        if n.shape is not None and n.shape.role == "Shape":
            out.update(n.shape.peers)
        todo.extend(table.by_parent.get(n.id, ()))
    return frozenset(out)


def set_visibility(sim: Any, node: Node, viewer: Node, visible: bool) -> None:
    """Webots' ``setVisibility``: ``node``'s shapes (and those inside it) left out of, or put back into, what
    one Camera, Lidar or RangeFinder sees (its pixel rays, beams, the rays past semi-transparent
    surfaces) or the Viewpoint's pictures (exportImage, snapshots). Shadows and other devices keep them."""
    if viewer.scenery and viewer.type == "Viewpoint":
        hidden = sim.viewpoint_hidden
    else:
        n = _nested_of(sim, viewer) if viewer.nested else None
        device = None if n is None or not n.device or n.owner_kind != "Robot" else \
            sim.robots[n.owner_key].devices.get(n.device)
        if device is None or device.kind not in _SEEING:
            raise ValueError(f"'from' ({_what(viewer)}) is not the viewpoint or a camera, lidar or range-finder device")
        hidden = device.hidden
    if visible:
        hidden.pop(node.id, None)
        return
    shapes = _node_shapes(sim, node)
    if not shapes:          # nothing of it is seen (a light, a device without shapes): nothing to hide
        hidden.pop(node.id, None)
        return
    pairs = len(sim.viewpoint_hidden) + sum(len(d.hidden) for r in sim.robots.values() for d in r.devices.values())
    if node.id not in hidden and pairs >= MAX_HIDDEN:
        raise ValueError(f"{MAX_HIDDEN} nodes are hidden from devices already (at most {MAX_HIDDEN} pairs): "
                         f"{_what(node)} not hidden; show one again first")
    hidden[node.id] = shapes


def _enclose(a: tuple[np.ndarray, float] | None, centre: np.ndarray, radius: float) -> tuple[np.ndarray, float]:
    """The smallest sphere holding sphere ``a`` and (``centre``, ``radius``) (WbBoundingSphere's merge)."""
    if a is None:
        return centre, radius
    c, r = a
    gap = float(np.linalg.norm(centre - c))
    if gap + radius <= r:
        return c, r
    if gap + r <= radius:
        return centre, radius
    grown = (gap + r + radius) / 2.0
    return c + (centre - c) * ((grown - r) / gap), grown


def bounding_sphere(sim: Any, node: Node) -> tuple[np.ndarray, float] | None:
    """A node's world bounding sphere as Webots merges it: each of its shapes' spheres (a primitive's
    about its centre, ``textures.bounding_radius``; a mesh's Ritter sphere of its world corners)
    enclosed one after the other, in shape order; None for a node without a (finite) shape."""
    from sensorium.server.sim.scene import primitive_from_model
    from sensorium.server.world.geometry import Mesh
    from sensorium.server.world.textures import bounding_radius
    scene = sim.scene
    sphere: tuple[np.ndarray, float] | None = None
    for shape in sorted(_node_shapes(sim, node) - scene.removed_shapes):
        g = scene.shape_model(shape).geometry
        pose = scene.shape_pose(shape)
        if isinstance(g, wm.Mesh | wm.Triangles | wm.ElevationGrid):
            prim = primitive_from_model(g, scene.base_dir)
            pts = pose.apply(prim.vertices) if isinstance(prim, Mesh) else pose.apply(np.zeros((1, 3)))
            a, b = _far_pair(pts)
            own = ((pts[a] + pts[b]) / 2.0, float(np.linalg.norm(pts[a] - pts[b])) / 2.0)
            for p in pts:
                own = _enclose(own, p, 0.0)
            sphere = _enclose(sphere, *own)
            continue
        radius = bounding_radius(g)
        if math.isfinite(radius):
            sphere = _enclose(sphere, pose.translation.astype(np.float64), radius)
    return sphere


def _far_pair(pts: np.ndarray) -> list[int]:
    """Ritter's start: the corner farthest from the first one, then the one farthest from it."""
    a = int(np.argmax(((pts - pts[0]) ** 2).sum(axis=1)))
    return [a, int(np.argmax(((pts - pts[a]) ** 2).sum(axis=1)))]


def move_viewpoint(sim: Any, node: Node) -> None:
    """Webots' ``moveViewpoint`` (WbViewpoint::moveViewpointToObject): the Viewpoint's position moved so
    that the node's bounding sphere fills the view (``viewshot.framing_position``), its orientation kept.
    Webots animates the move over about a second of wall time; headless it is there at once. A node
    inside a robot or solid without shapes frames its nearest ancestor with some, up to that top-level
    node (WbNodeUtilities::boundingSphereAncestor); a top-level node without any (Webots: an empty
    bounding sphere) leaves the Viewpoint where it is."""
    sphere = bounding_sphere(sim, node)
    while sphere is None and node.nested:
        node = node_by_id(sim, _nested_of(sim, node).parent)
        sphere = bounding_sphere(sim, node)
    if sphere is None:
        return
    vp = next(s for s in _scenery(sim) if s.type == "Viewpoint")
    sim.viewpoint_loaded = dict(vp.fields) if sim.viewpoint_loaded is None else sim.viewpoint_loaded
    vp.fields["position"] = list(viewshot.framing_position(viewshot.viewpoint_of(sim), *sphere))


def _move_viewpoint(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    move_viewpoint(sim, node_by_id(sim, a.node))
    return {"success": True}


def _set_visibility(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    set_visibility(sim, node_by_id(sim, a.node), node_by_id(sim, a.from_node), a.visible)
    return {"success": True}


def actual_field(sim: Any, node: Node, field: str, level: int = -1) -> str:
    """Webots' ``getActualField``: the name of the node's own field (``getField``, the one the scene tree
    shows and a Supervisor sets) that the field ``field`` of ``level`` takes its value from; '' for Webots'
    NULL. A node's own field is its own actual field. A PROTO instance's base-node field (level 0) or a field
    of a PROTO it is built on (level >= 2) is linked to the interface field that passes through IS unchanged to
    the same base-node field (``ProtoField.base``: the chain from the interface down to that field has one
    field at each level, so the shared base names it); a field no interface field reaches that way is NULL."""
    level = _level(node, level)
    if field not in _fields(sim, node, level):
        return ""
    if level == 1 or not node.interface:
        return field
    if level == 0:
        base: str | None = field
    else:
        base = next((f.base for f in node.interface[level - 1].fields if f.name == field), None)
    own = node.interface[0].fields
    return next((f.name for f in own if base is not None and f.base == base), "")


_SOLID_ORDER = ("translation", "rotation", "scale", "children", "name", "model", "radarCrossSection", "controller",
                "customData", "supervisor", "synchronization", "battery", "cpuConsumption")
_JOINT_ORDER = ("jointParameters", "jointParameters2", "jointParameters3", "device", "device2", "device3", "endPoint")
_LIGHT_ORDER = ("ambientIntensity", "attenuation", "beamWidth", "color", "cutOffAngle", "direction", "intensity",
                "location", "on", "radius", "castShadows")
DECLARATION_ORDER: dict[str, tuple[str, ...]] = {
    "WorldInfo": ("title", "gravity", "basicTimeStep", "inkEvaporation", "coordinateSystem", "gpsCoordinateSystem",
                  "gpsReference", "randomSeed"),
    "Viewpoint": ("fieldOfView", "orientation", "position", "description", "near", "far", "exposure", "follow"),
    **{kind: _LIGHT_ORDER for kind in LIGHTS},
    **{kind: _JOINT_ORDER for kind in nested.JOINT_DEVICES},
}
"""Webots' declaration order of the fields served here (its nodes' .wrl files), for the node types whose
served fields are not built in that order; any other type's (a Solid, a device, a Pose: ``_SOLID_ORDER``;
a Shape's nodes, visual nodes: their tables, written in Webots' order) keep it."""


def field_names(sim: Any, node: Node, level: int = 0) -> list[str]:
    """The fields Sensorium serves of the node's base node (level 0) or of its PROTO ``level``, in Webots'
    declaration order: what ``getNumberOfFields``/``getFieldByIndex`` of a base node and
    ``getNumberOfBaseNodeFields``/``getBaseNodeFieldByIndex`` count and list. Webots' other fields
    (``description``, ``boundingObject``, ``physics``, ...) are left out: they are not served here."""
    names = list(_fields(sim, node, level))
    if level >= 1:
        return names
    order = DECLARATION_ORDER.get(node.type, _SOLID_ORDER)
    rank = {name: k for k, name in enumerate(order)}
    return sorted(names, key=lambda name: (rank.get(name, len(order)), names.index(name)))


def get_proto(sim: Any, node: Node, level: int) -> dict:
    """Webots' ``getProto()`` (level 1) and ``getParent()`` (level + 1): the PROTO's name, whether it is
    built on another PROTO, its interface fields' names; type_name '' for none. Level 0: the base node,
    its type name and the fields served here (:func:`field_names`)."""
    if level == 0:
        return {"type_name": node.type, "derived": False, "fields": field_names(sim, node, 0)}
    if not 1 <= level <= len(node.interface):
        return {"type_name": "", "derived": False, "fields": []}
    proto = node.interface[level - 1]
    return {"type_name": proto.name, "derived": proto.derived, "fields": [f.name for f in proto.fields]}


def from_proto_def(sim: Any, node: Node, name: str) -> tuple[Node | None, str]:
    """Webots' ``getFromProtoDef``: the node of PROTO instance ``node``'s body with DEF ``name`` (Webots'
    scope: :func:`nested.inner_def`), or None with a line when there is none to give: ``node`` is no PROTO
    instance, one Sensorium builds in (its body is not read), one whose body is not searched here (a light,
    an appearance, a Background PROTO), or the DEF names a node Sensorium does not serve (a Physics node,
    ...: why); None without a line when the body has no such DEF (Webots' NULL)."""
    if not node.proto:
        return None, "'node' is not a PROTO node"
    if not node.interface:
        return None, (f"PROTO {node.proto} is built into Sensorium here (its file was not read): the DEF names of its "
                      "body are not known")
    if node.scenery or node.visual or node.type in LIGHTS or (node.nested and _nested_of(sim, node).shape is not None):
        return None, (f"the body of PROTO {node.proto} ({_what(node)}) is not searched here: DEF names are found in "
                      "the bodies of robots, solids and the PROTO instances inside them")
    found = nested.inner_def(_table(sim), node.id, name)
    if isinstance(found, str):
        return None, f"DEF {name} of PROTO {node.proto}'s body ({_what(node)}) names {found}"
    if found is None:
        return None, ""
    return node_by_id(sim, found), ""


def _from_proto_def(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    found, note = from_proto_def(sim, node_by_id(sim, a.node), a.name)
    return {**node_ref(sim, found), "note": note}


def change_item(sim: Any, node: Node, field: str, op: str, index: int, value: Any, level: int = -1) -> list[str]:
    """Webots' ``setMF*``/``insertMF*``/``removeMF`` of every MF type: on an imported line or point set's MF
    fields (visuals.py) and a shape's texture url; on a top-level solid's PROTO interface field, which builds
    the solid again (:func:`_regenerate`: returns the lines of the values corrected); any other MF field (a
    robot's PROTO interface field too) is read-only here (one line, nothing changed)."""
    level = _level(node, level)
    fields = _fields(sim, node, level)
    entry = fields.get(field)
    what = visuals.what(_vnode(sim, node)) if node.visual and node.id >= visuals.FIRST_ID else _what(node)
    if level >= 1:
        what = f"PROTO {node.interface[level - 1].name} ({what})"
    if entry is None:
        raise ValueError(f"{what} has no field {field!r} here (fields: {', '.join(fields) or 'none'})")
    kind = entry[0]
    if not kind.startswith("MF"):
        raise ValueError(f"field {field!r} of {what} is an {kind}, not a list: set it as a whole")
    if _battery_field(node, level, field):
        _set_battery_item(sim, node, f"field {field!r} ({kind}) of {what}", op, index, value)
        return []
    if level == 1 and _rebuilds(node):
        return _regenerate(sim, node, field, kind, _changed_items(sim, node, field, kind, entry, op, index, value))
    if level >= 1:
        raise ValueError(f"field {field!r} ({kind}) of {what}: its items are read-only here (Webots regenerates the "
                         "node when a PROTO field is changed; Sensorium builds again only a top-level solid, not a "
                         "robot, and a Supervisor changes the items of an imported line or point set's fields); "
                         "nothing changed")
    if level == 0 and node.interface:
        raise ValueError(f"field {field!r} ({kind}) of {what} is a PROTO internal field (getBaseNodeField): its "
                         "items are read-only, as in Webots; nothing changed")
    ref = _nested_of(sim, node).shape if node.nested else None
    if ref is not None and ref.type == "ImageTexture" and field == "url":      # a texture's image (appearance.py)
        return appearance.change_url(sim, ref, node, op, index, value)
    if not (node.visual and node.id >= visuals.FIRST_ID and visuals.settable(_vnode(sim, node), field)):
        if node.visual and node.id >= visuals.FIRST_ID:
            raise ValueError(visuals.read_only_line(_vnode(sim, node), field, kind))
        raise ValueError(f"field {field!r} ({kind}) of {what}: its items are read-only here (a Supervisor changes "
                         "the items of an imported line or point set's fields only); nothing changed")
    visuals.change(_vnode(sim, node), field, op, index, value)
    return []


def _battery_field(node: Node, level: int, field: str) -> bool:
    """Whether ``field`` at ``level`` is a top-level robot's ``battery``: its own, or its PROTO's field passing
    straight through IS to it."""
    if node.type != "Robot" or node.nested or node.scenery or node.visual:
        return False
    if level == 0:
        return field == "battery" and not node.interface
    return level == 1 and any(f.name == field and f.base == "battery" and f.type == "MFFloat"
                              for f in node.interface[0].fields)


_ITEM_SIZES = {"MFVec2f": 2, "MFVec3f": 3, "MFColor": 3, "MFRotation": 4}


def _changed_items(sim: Any, node: Node, field: str, kind: str, entry: tuple, op: str, index: int,
                   value: Any) -> list:
    """A PROTO field's list with one item set, inserted or removed (Webots' index rules: negative from the end;
    an insert at -1 is after the last), each item of the field's type (one line otherwise)."""
    try:
        items = list(entry[1](sim, node))
    except NotKept as exc:
        raise ValueError(f"{exc}: its items cannot be changed here; nothing changed") from None
    at = item_position(f"field {field!r} ({kind}) of {_what(node)}", op, index, len(items))
    if op == "remove":
        del items[at]
        return items
    size = _ITEM_SIZES.get(kind)
    item_kind = {"MFBool": "SFBool", "MFInt32": "SFInt32", "MFFloat": "SFFloat", "MFString": "SFString"}.get(
        kind, {2: "SFVec2f", 3: "SFVec3f", 4: "SFRotation"}.get(size or 0, kind))
    _check_value(field, item_kind, value)
    item = [float(v) for v in value] if size else value
    if op == "insert":
        items.insert(at, item)
    else:
        items[at] = item
    return items


_NOT_REBUILT = ("Webots regenerates the node when such a PROTO field is set; Sensorium builds again only a top-level "
                "solid (a robot's controller, devices and lockstep slot are built once here: a robot is not "
                "rebuilt) and otherwise sets only the PROTO fields that pass straight through IS to a field it sets "
                "(a top-level robot's or solid's translation and rotation, a light's fields)")


def _rebuilds(node: Node) -> bool:
    """Whether a set of one of the node's own PROTO fields builds it again (Webots' regeneration): a
    top-level solid that is a PROTO instance (a .wbt world's or an imported one)."""
    return node.type == "Solid" and bool(node.interface) and not (node.nested or node.scenery or node.visual)


_INT32 = (-(1 << 31), (1 << 31) - 1)


def _check_value(field: str, kind: str, value: Any) -> None:
    """A value a Supervisor sets as a whole (``setSF*``, an MF item, a PROTO field that rebuilds its node): of
    the field's type, numbers finite, an SFInt32 within 32 bits (one line otherwise)."""
    if kind == "SFBool":
        ok = isinstance(value, bool)
    elif kind == "SFInt32":
        ok = isinstance(value, int) and not isinstance(value, bool) and _INT32[0] <= value <= _INT32[1]
    elif kind == "SFFloat":
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    elif kind == "SFString":
        ok = isinstance(value, str)
    elif kind in _VECTOR_SIZES:
        ok = isinstance(value, list) and len(value) == _VECTOR_SIZES[kind] and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value)
    else:
        raise ValueError(f"field {field!r} is an {kind}: set it item by item (setMF*, insertMF*, removeMF)" if
                         kind.startswith("MF") else f"field {field!r} is an {kind}: not set as a whole here")
    if not ok:
        want = {"SFBool": "true or false", "SFInt32": "a whole number within 32 bits", "SFFloat": "a finite number",
                "SFString": "a string"}.get(kind, f"{_VECTOR_SIZES.get(kind)} finite numbers")
        raise ValueError(f"field {field!r} is an {kind}: takes {want}, got {value!r}")


def _regenerate(sim: Any, node: Node, field: str, kind: str, value: Any) -> list[str]:
    """Webots' regeneration of PROTO instance ``node`` (a top-level solid) with ``field`` set to ``value``
    (sim/regenerate.py): it keeps its id, DEF, name, pose now and place among the root's children (built at
    the instance's written pose, as loaded, then moved where a Supervisor put it: its template reads the
    written ``translation`` and ``rotation``); the nodes inside it were Webots' internal nodes of the old
    body: they read as removed, and those of the new body are served with new ids (:func:`_forget`). One line
    and nothing changed when it does not build; returns the lines of the values corrected as in a world file."""
    from sensorium.server.sim.imports import ImportRefused
    from sensorium.server.sim.regenerate import regenerate

    table = _table(sim)              # numbered before the solid changes (its old nodes keep their ids)
    proto = node.interface[0]
    key = str(node.key)
    now = sim.scene.solid_poses[key]
    built = pose_from_model(next(s for s in reversed(sim.world.solids) if s.name == key).pose)
    moved = not (np.array_equal(now.translation, built.translation) and np.array_equal(now.rotation, built.rotation))
    corrected: list[str] = []
    try:
        regenerate(sim, key, node.id, {field: (kind, value)}, corrected)
    except (ImportRefused, KeyError, OSError, RecursionError) as exc:
        text = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        raise ValueError(f"field {field!r} ({kind}) of PROTO {proto.name} ({_what(node)}) not set: the solid does "
                         f"not build with that value: {text}; nothing changed") from None
    if moved:                        # built where the instance says, as loaded (a reset puts it back there bit for
        sim.place_solid(key, now)    # bit), then moved where the Supervisor had put it
    _forget(sim, table, node.id, key)
    return corrected


def _forget(sim: Any, table: nested.Table, owner: int, key: str) -> None:
    """The nodes inside top-level solid ``owner`` leave the tree (its body was built again): their ids read
    as removed nodes and no walk, DEF or getFromProtoDef finds them; the new body's nodes take their place,
    with new ids (Webots' regenerated node holds new internal nodes)."""
    nested.drop(table, owner)
    nested.add_solid(sim, table, owner, key, next(s for s in reversed(sim.world.solids) if s.name == key))


def set_field(sim: Any, node: Node, field: str, value: Any, level: int = -1) -> list[str]:
    """Webots' ``setSF*``: the field's value changes at once. Returns the lines Webots would print in its
    console (the values corrected when a PROTO field set builds a solid again)."""
    level = _level(node, level)
    what = f"{node.type} {node.name or node.id!r}"
    fields = _fields(sim, node, level)      # a level past the node's PROTO chain: one line
    if level == 0 and node.interface:
        raise ValueError(f"field {field!r} of {what} is a PROTO internal field (getBaseNodeField), read-only as in "
                         f"Webots: set the field of PROTO {node.interface[0].name} instead")
    if level > 1:
        raise ValueError(f"field {field!r} of {what} belongs to PROTO {node.interface[level - 1].name}, which PROTO "
                         f"{node.interface[0].name} is built on: read-only, as in Webots")
    entry = fields.get(field)
    if entry is None:
        kind_of = f"PROTO {node.interface[0].name} " if level == 1 else ""
        raise ValueError(f"{what} has no {kind_of}field {field!r} here (fields: {', '.join(fields) or 'none'})")
    kind, _, setter = entry
    if setter is None and level == 1:
        declared = next(f for f in node.interface[0].fields if f.name == field)
        if _rebuilds(node) and declared.base != "name":
            _check_value(field, kind, value)
            return _regenerate(sim, node, field, kind, value)
        why = (f"it passes to the base node's {declared.base!r}, which is read-only here" if declared.base
               and declared.base in _base_fields(sim, node) else _NOT_REBUILT)
        raise ValueError(f"field {field!r} ({kind}) of PROTO {node.interface[0].name} ({what}) is read-only here: "
                         f"{why}; nothing changed")
    if setter is None and node.visual and node.id >= visuals.FIRST_ID:
        raise ValueError(visuals.read_only_line(_vnode(sim, node), field, kind))
    if setter is None and node.nested and node.type == "ImageTexture" and field == "url":
        raise ValueError(f"field 'url' ({kind}) of {_what(node)} is changed item by item (setMFString, "
                         "insertMFString, removeMF), not set as a whole; nothing changed")
    if setter is None and node.nested and node.type in appearance.TYPES:
        raise ValueError(f"field {field!r} ({kind}) of {_what(node)} is read-only here: of a shape's nodes a "
                         "Supervisor sets a Material's diffuseColor, emissiveColor and transparency, a "
                         "PBRAppearance's baseColor, roughness, metalness, transparency and emissiveColor and an "
                         "ImageTexture's url, repeatS, repeatT and filtering only")
    if setter is None and node.nested and field in ("translation", "rotation") and node.type in _SOLID_POSES \
            and _nested_of(sim, node).owner_kind == "Solid":      # (one written in a PROTO's body: no place)
        raise ValueError(f"field {field!r} ({kind}) of {_what(node)} is a PROTO internal field, read-only as in "
                         "Webots: set the PROTO's fields instead; nothing changed")
    if setter is None and node.nested:
        raise ValueError(f"field {field!r} ({kind}) of {what} is read-only here: a Supervisor moves and changes "
                         "top-level robots, solids and lights only, not the nodes inside them")
    if setter is None and node.scenery and node.type in ("Pose", "Transform", "Group"):
        raise ValueError(f"field {field!r} ({kind}) of {node.type} {node.def_name or node.id!r} is read-only here: "
                         "a top-level group's solids are moved one by one (getMFNode(i) of its children); "
                         "nothing changed")
    if setter is None:
        raise ValueError(f"field {field!r} ({kind}) of {what} is read-only here")
    _check_value(field, kind, value)
    setter(sim, node, value)
    return []


def node_pose(sim: Any, node: Node) -> dict:
    pose = nested.world_pose(sim, _nested_of(sim, node)) if node.nested else \
        _pose(sim, node) if node.type in ("Robot", "Solid") else None
    if pose is None and node.scenery and node.type in ("Pose", "Transform") and _group_members(sim, node):
        written = _scenery(sim)[int(node.key)].fields      # a top-level group's: the world file's, fixed
        rotation = [float(v) for v in written.get("rotation", [0.0, 0.0, 1.0, 0.0])]
        return {"position": [float(v) for v in written.get("translation", [0.0, 0.0, 0.0])],
                "orientation": [float(v) for v in axis_angle_matrix(rotation[:3], rotation[3]).reshape(9)]}
    if pose is None:                                 # Webots: NaN for a node that is no Pose
        return {"position": [math.nan] * 3, "orientation": [math.nan] * 9}
    return {"position": [float(v) for v in pose.translation],
            "orientation": [float(v) for v in np.asarray(pose.rotation).reshape(9)]}


def center_of_mass(sim: Any, node: Node) -> list[float]:
    """Webots' ``getCenterOfMass``: the mass-weighted centre of a Solid (a Robot, a device) and of the
    Solids inside it with a Physics node, in world coordinates now (a driving robot's moves with it, a
    joint's end point with the joint); 0 0 0 for one without Physics (Webots' zero vector); NaN for a
    node that is no Solid (Webots warns and answers NaN)."""
    nan = [math.nan] * 3
    if node.nested:
        me = _nested_of(sim, node)
        if me.shape is not None or me.local is None or me.type in ("Pose", "Transform"):
            return nan
        own = me.mass
        table = _table(sim)
        inside: list[nested.Nested] = []
        stack = [me.id]
        while stack:
            for child in table.by_parent.get(stack.pop(), ()):
                inside.append(child)
                stack.append(child.id)
    elif node.type in ("Robot", "Solid") and not node.visual:
        model = sim.robots[node.key].model if node.type == "Robot" else \
            next((s for s in sim.world.solids if s.name == node.key), None)
        own = None if model is None else model.mass
        inside = [n for n in _table(sim).by_owner.get(node.id, ())]
    else:
        return nan
    if own is None:
        return [0.0, 0.0, 0.0]
    pose = nested.world_pose(sim, me) if node.nested else _pose(sim, node)
    weighted = [(own.kg, pose.rotation @ np.asarray(own.center) + pose.translation)]
    for n in inside:
        at = None if n.mass is None else nested.world_pose(sim, n)
        if at is not None:
            weighted.append((n.mass.kg, at.rotation @ np.asarray(n.mass.center) + at.translation))
    total = sum(kg for kg, _ in weighted)
    return [float(v) for v in sum(kg * p for kg, p in weighted) / total]


def _top_solid(node: Node) -> None:
    """Webots' refusal of a static-balance or contact-points query on anything but a top-level solid or robot."""
    if node.nested or node.visual or node.type not in ("Robot", "Solid"):
        raise ValueError("it can exclusively be used with a top Solid, not " + ("the root" if node.id == 0 else _what(node)))


def static_balance(sim: Any, node: Node) -> bool:
    """Webots' ``getStaticBalance`` of a top-level solid or robot (sim/balance.py): with physics, whether
    its centre of mass (:func:`center_of_mass`; a solid given no mass: its shapes' volumes') seen from
    above is over the support polygon of where its bounding shapes touch the ground now; False without
    physics or touching nothing. Anything else: Webots' warning as the one line (the client answers
    false, as Webots' does)."""
    _top_solid(node)
    if node.type == "Robot":
        state = sim.robots[node.key]
        return state.model.mass is not None and balance.robot_balance(sim, state, center_of_mass(sim, node))
    model = next(s for s in sim.world.solids if s.name == node.key)
    return model.physics and balance.solid_balance(sim, node.key, None if model.mass is None
                                                   else center_of_mass(sim, node))


def _touching_through(points: np.ndarray, tags: list, moving: set) -> tuple[np.ndarray, list]:
    """The contact points (flat or (n, 3)) whose solid's tag is in ``moving``, and their tags."""
    keep = [k for k, tag in enumerate(tags) if tag in moving]
    return points.reshape(-1, 3)[keep], [tags[k] for k in keep]


def contact_points(sim: Any, node: Node, descendants: bool) -> dict:
    """Webots' ``getContactPoints`` of a top-level solid or robot (sim/balance.py): where its bounding
    shapes (with ``descendants``, the solids' inside it too) touch the ground now, in world axes, each
    with the id of the Solid whose shape touches (a nested solid's as the nested table numbered it: a
    robot's by its entry, a solid's by its path). Webots' physics makes no contact between static
    geometries: a top without Physics touches through none of its own shapes, but with ``descendants``
    through its nested solids with Physics (and those inside them, merged into their bodies), as Webots
    counts every contact whose solid's top solid is the node. Anything else: one line."""
    _top_solid(node)
    inside = [n for n in _table(sim).by_owner.get(node.id, ()) if n.shape is None and n.field != "jointParameters"]
    if node.type == "Robot":
        state = sim.robots[node.key]
        static = state.model.mass is None
        if static and not descendants:
            return {"points": [], "nodes": []}
        points, owners = balance.robot_contacts(sim, state, descendants)
        if static:                              # only the nested solids physics moves touch
            points, owners = _touching_through(points, owners, balance.dynamic_entries(list(state.model.nodes)))
        ids = [node.id if k < 0 or k >= len(inside) else inside[k].id for k in owners]
    else:
        model = next(s for s in sim.world.solids if s.name == node.key)
        if not model.physics and not descendants:
            return {"points": [], "nodes": []}
        points, paths = balance.solid_contacts(sim, node.key, descendants)
        if not model.physics:
            points, paths = _touching_through(points, paths, balance.dynamic_solids(model))
        by_path = {n.path: n.id for n in inside if n.path}
        ids = [by_path.get(path, node.id) for path in paths]
    return {"points": [float(v) for v in points.reshape(-1)], "nodes": ids}


def node_velocity(sim: Any, node: Node) -> list[float]:
    """Webots' ``getVelocity``: a driven robot's from its kinematic drive's last step (world axes,
    linear m/s then angular rad/s), a node inside it moving with it; a top-level solid falling after a
    gripper let it go: −g·t along the up (sim/falling.py); anything else never moves by itself: zeros."""
    if node.nested:
        return nested.velocity(sim, _nested_of(sim, node))
    if node.type == "Robot":
        drive = sim.robots[node.key].drive
        if drive is not None:
            return drive.velocity()
    elif node.type == "Solid" and not node.visual and sim.falls:
        falling = sim.falls.velocity(node.key, sim.time_ms)
        if falling is not None:
            return falling
    return [0.0] * 6


# ---------------------------------------------------------------------- the services
# handler(sim, lockstep, calling robot, validated args) -> result; ValueError = INVALID_ARGUMENT

def _set_field(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    if a.index is not None:          # an MF field's item: set, inserted or removed
        corrected = change_item(sim, node_by_id(sim, a.node), a.field, a.op, a.index, a.value, a.level)
    else:
        corrected = set_field(sim, node_by_id(sim, a.node), a.field, a.value, a.level)
    return {"success": True, LOG: corrected} if corrected else {"success": True}


def remove_node(sim: Any, node: Node) -> None:
    """Webots' ``node.remove()`` for what is a node here: a top-level solid or light, a Shape inside a
    robot or solid (``Scene.remove_shapes``: unseen from the next cast, a split mesh's pieces together; its
    node and those inside it read as removed). The root and robots are refused (a robot's controller, devices and lockstep slot cannot leave a running
    server here; Webots removes a robot, the calling one at the end of the step)."""
    if node.scenery:
        raise ValueError(f"{node.type} (node {node.id}) cannot be removed here: only top-level solids and lights "
                         "can (Sensorium does not simulate it)")
    if node.visual and node.id >= visuals.FIRST_ID:
        raise ValueError(f"{visuals.what(_vnode(sim, node))} cannot be removed here: of an imported Shape or Group "
                         "only the node at the root can be (remove it and import it again)")
    if node.visual:
        sim.remove_solid(node.key)
        return
    if node.nested and _imported_inside(sim, node):     # (an imported Shape too: its solid built without it)
        _remove_imported(sim, node)
        return
    ref = _nested_of(sim, node).shape if node.nested else None
    if ref is not None and ref.role == "Shape":      # a Shape inside a robot or solid: every piece of it unseen
        sim.scene.remove_shapes(ref.peers or (ref.index,))
        nested.drop_shape(_table(sim), node.id)
        return
    if node.nested and node.type in LIGHTS:     # a light inside a robot or solid: unlit from the next measurement
        model = _carried_model(sim, node)
        if model.node.body:      # (Webots names it by its usefulName: "DEF <its body's DEF> <type>")
            defs = [d.name for d in model.node.inner_defs if not d.role] or ([model.def_name] if model.def_name else [])
            name = f"DEF {defs[0]} {node.type}" if defs else node.type
            raise ValueError(f"Node '{name}' is internal to a PROTO and therefore cannot be deleted from a "
                             "Supervisor.")
        sim.scene.remove_carried_light(*_carrier(sim, node))
        nested.drop_shape(_table(sim), node.id)
        return
    if node.nested and node.type in _SOLID_POSES and _nested_of(sim, node).owner_kind == "Solid":
        _remove_solid_pose(sim, node)
        return
    if node.nested:
        raise ValueError(f"{node.type} {node.name or node.def_name or node.id!r} (node {node.id}) cannot be removed "
                         "here: only top-level solids and lights and the Shapes inside robots and solids can, not "
                         "the other nodes inside a robot or solid")
    if node.type == "Solid":
        sim.remove_solid(node.key)
    elif node.type in LIGHTS:
        sim.remove_light(node.key)
    elif node.type == "Robot":
        raise ValueError(f"robot {node.name!r} (node {node.id}) cannot be removed here: only top-level "
                         "solids and lights can (a departure from Webots, which removes robots too)")
    else:
        raise ValueError("the root node cannot be removed")


_SOLID_POSES = frozenset({"Pose", "Transform", "Group"})


def _imported_inside(sim: Any, node: Node) -> bool:
    """A node a Supervisor imported inside a top-level solid, written in its parent's children (a Shape, a Pose, a
    solid: not an appearance or geometry inside a Shape)."""
    from sensorium.server.sim.regenerate import imported_line

    n = _nested_of(sim, node)
    return n.owner_kind == "Solid" and bool(n.at) and imported_line(n.at[0]) and n.field == "children" \
        and (n.shape is None or n.shape.role == "Shape")


def _remove_solid_pose(sim: Any, node: Node) -> None:
    """A Pose, Transform or Group inside a top-level solid removed with what it holds, as Webots removes a subtree:
    its Shapes unseen and its lights unlit from the next measurement, their nodes read as removed. One holding a
    solid is refused (a nested solid's contact, radar and recognition parts stay with its top-level solid here),
    as is one a PROTO's body writes (Webots' line)."""
    table = _table(sim)
    n = _nested_of(sim, node)
    if not n.at:             # (Webots names it by its usefulName: "DEF <its body's DEF> <type>")
        defs = sorted({k for found in (table.inner or {}).values() for k, v in found.items() if v == n.id})
        name = f"DEF {defs[0]} {n.type}" if defs else n.type
        raise ValueError(f"Node '{name}' is internal to a PROTO and therefore cannot be deleted from a Supervisor.")
    inside: list[nested.Nested] = []
    todo = [n.id]
    while todo:
        for c in table.by_parent.get(todo.pop(), ()):
            inside.append(c)
            todo.append(c.id)
    held = next((c for c in inside if c.type == "Solid" and c.shape is None), None)
    if held is not None:
        raise ValueError(f"{_what(node)} cannot be removed here: it holds Solid {held.name!r} (node {held.id}), and "
                         "only the Shapes and lights inside a solid's Poses and Groups leave with them; remove the "
                         "top-level solid instead")
    shapes: set[int] = set()
    for c in inside:
        if c.shape is not None and c.shape.role == "Shape":
            shapes.update(c.shape.peers or (c.shape.index,))
        elif c.light >= 0:
            sim.scene.remove_carried_light(*_carrier(sim, _nested_node(c)))
    if shapes:
        sim.scene.remove_shapes(sorted(shapes))
    nested.drop_shape(table, n.id)


def _remove(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    remove_node(sim, node_by_id(sim, a.node))
    return {"success": True}


JOINT_AXES = {"HingeJoint": 1, "SliderJoint": 1, "Hinge2Joint": 2, "BallJoint": 3}
"""Each joint type's axes, Webots' ``setJointPosition`` indices 1..n (its ``device``, ``device2``, ``device3``)."""
_AXES_LINE = {1: "SliderJoint and HingeJoint only support index 1", 2: "Hinge2Joint only supports index 1 or 2",
              3: "BallJoint only supports index 1, 2, or 3"}


def _what(node: Node) -> str:
    return f"{node.type} {node.def_name or node.name or str(node.key)!r} (node {node.id})"


def set_joint_position(sim: Any, node: Node, position: float, index: int) -> list[str]:
    """Webots' ``setJointPosition`` (WbJoint::setPosition): the joint's axis ``index`` at
    ``position`` at once, what rides on it with it, the axis's motor targeting it (its
    multiplier and limits applied: Webots' warning line returned when it clamps). A joint here moves
    by its motor: an axis without one is refused (one line)."""
    if index < 1:
        raise ValueError("called with an invalid 'index'. Only values greater than or equal to 1 are supported")
    axes = JOINT_AXES.get(node.type) if node.nested else None
    if axes is None:
        raise ValueError(f"called with a 'node' argument which is not a joint node ({_what(node)})")
    if index > axes:
        raise ValueError(f"called with an invalid 'index'. {_AXES_LINE[axes]}")
    check_joint_position(position)
    n = _nested_of(sim, node)
    field = ("device", "device2", "device3")[index - 1]
    motor = next((c.device for c in _table(sim).by_parent.get(n.id, ())
                  if c.field == field and c.type in nested.MOTORS and c.device), "")
    robot = sim.robots.get(n.owner_key) if n.owner_kind == "Robot" else None
    if robot is None or motor not in robot.motors:
        raise ValueError(f"{_what(node)} has no motor on its axis {index} here: Sensorium moves a joint by its "
                         "motor only (a joint without one stays where the world file puts it)")
    line = robot.motors[motor].place(position)
    sim.joints_moved(robot)
    return [f"robot {robot.name!r}: wb_supervisor_node_set_joint_position(): {line}"] if line else []


def check_joint_position(position: float) -> None:
    """A joint position a Supervisor sets: finite, within ``MAX_COORDINATE_M`` (m or rad: a slider's
    end point stays where a pose set at run time may be)."""
    if not (math.isfinite(position) and abs(position) <= MAX_COORDINATE_M):
        raise ValueError(f"a joint's 'position' must be a finite number within ±{MAX_COORDINATE_M:g}, "
                         f"got {position!r}")


def _set_joint_position(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    return {"success": True, LOG: set_joint_position(sim, node_by_id(sim, a.node), a.position, a.index)}


def _inside(table: nested.Table, n: nested.Nested) -> list[nested.Nested]:
    """A nested node and every node inside it (children, end points, devices, parameters)."""
    out, todo = [], [n]
    while todo:
        m = todo.pop()
        out.append(m)
        todo.extend(table.by_parent.get(m.id, ()))
    return out


def state_scope(sim: Any, node: Node) -> states.Scope:
    """What ``saveState``/``loadState`` cover for a node: a robot's pose, joints and LEDs; a
    top-level solid's pose; a node inside a robot, the joints and LEDs inside it (a node inside a
    solid has nothing that moves here). The root, lights and the nodes not simulated are refused."""
    what = _what(node)
    if node.nested:
        n = _nested_of(sim, node)
        if n.owner_kind != "Robot":
            return states.Scope(what)
        robot = sim.robots[n.owner_key]
        inside = _inside(_table(sim), n)
        motors = tuple(dict.fromkeys(m.device or m.motor for m in inside if (m.device or m.motor) in robot.motors))
        leds = tuple(m.device for m in inside if m.device in robot.devices and robot.devices[m.device].kind == "LED")
        return states.Scope(what, robot=n.owner_key, motors=motors, leds=leds)
    if node.type == "Robot":
        robot = sim.robots[node.key]
        leds = tuple(name for name, d in robot.devices.items() if d.kind == "LED")
        return states.Scope(what, robot=node.key, own_pose=True, motors=tuple(robot.motors), leds=leds)
    if node.type == "Solid" and not node.scenery:
        return states.Scope(what, solid=str(node.key))
    raise ValueError(f"{what} has no state here: robots, top-level solids and the nodes inside them have one")


def _kept(sim: Any, attribute: str, make: Callable[[], T]) -> T:
    """What the Supervisor keeps for a simulation beside it (saved states, labels), made at first use."""
    kept = getattr(sim, attribute, None)
    if kept is None:
        kept = make()
        setattr(sim, attribute, kept)
    return kept


def _states(sim: Any) -> states.States:
    return _kept(sim, "_node_states", states.States)


def _save_state(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    node = node_by_id(sim, a.node)
    scope = state_scope(sim, node)
    _states(sim).save(sim, node.id, scope, a.state)
    if scope.solid is not None:       # with the Poses inside it as written now (WbNode::save covers them)
        _kept(sim, "_pose_states", dict)[(node.id, a.state)] = _posed_values(sim, node, loaded=False)
    return {"success": True}


def _load_state(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    node = node_by_id(sim, a.node)
    scope = state_scope(sim, node)
    _states(sim).load(sim, node.id, scope, a.state)
    if scope.solid is not None:
        saved = _kept(sim, "_pose_states", dict).get((node.id, a.state))
        _restore_posed(sim, node, _posed_values(sim, node, loaded=True) if saved is None else saved)
    return {"success": True}


_POSE_DEFAULTS = {"translation": (0.0, 0.0, 0.0), "rotation": (0.0, 0.0, 1.0, 0.0)}


def _posed_values(sim: Any, node: Node, loaded: bool) -> dict[int, dict[str, Any]]:
    """The translation and rotation of each Pose and Transform inside top-level solid ``node`` that a
    Supervisor may set, as its world file writes them now (``loaded``: as loaded), by node id."""
    from sensorium.server.sim.regenerate import written_fields

    table, out = _table(sim), {}
    posed = getattr(sim, "_posed", {}).get(node.key, {})
    for n in table.by_owner.get(node.id, ()):
        if n.own is None or n.type not in ("Pose", "Transform") or not n.at:
            continue
        at = (n.at[0], n.at[1])
        values = posed[at][1] if loaded and at in posed else written_fields(sim, node.key, at, tuple(_POSE_DEFAULTS))
        if values is not None:
            out[n.id] = {k: _POSE_DEFAULTS[k] if v is None else tuple(v) for k, v in values.items()}
    return out


def _restore_posed(sim: Any, solid: Node, values: dict[int, dict[str, Any]]) -> None:
    """Each Pose inside top-level solid ``solid`` back at its saved translation and rotation (through its
    set: the solid built again; a set changes no other Pose's values, so they are read once)."""
    now = _posed_values(sim, solid, loaded=False)
    for node_id, saved in values.items():
        if node_id not in now:        # (removed since)
            continue
        node = node_by_id(sim, node_id)
        for field, value in saved.items():
            if now[node_id][field] != value:
                _set_solid_pose(sim, node, field, list(value))


def insert_index(position: int, count: int) -> int:
    """Webots' import position in a list of ``count`` nodes: 0 the first place, -1 after the last,
    -2 before the last, ...; a position past either end is the nearest end."""
    index = position if position >= 0 else count + 1 + position
    return min(max(index, 0), count)


def import_nodes(sim: Any, node: Node, field: str, position: int, text: str,
                 warnings: list[str] | None = None) -> list[int]:
    """Webots' ``importMFNodeFromString`` on the root's ``children``: the string's solids and
    lights join the world from the next measurement, inserted at ``position`` (Webots' rule,
    :func:`insert_index`); returns their new ids. An SFNode field is Webots' ``importSFNodeFromString``
    (:func:`import_sf_node`); any other field is refused (Sensorium's nodes have no other MFNode field
    taking imports); a string that cannot be imported changes nothing (one line). ``warnings`` gets the
    values corrected as Webots corrects them (Webots prints them in its console)."""
    try:
        entry = _fields(sim, node).get(field) if node.id != 0 else None
    except (KeyError, ValueError):
        entry = None
    if entry is not None and entry[0] == "SFNode":        # importSFNodeFromString
        return [import_sf_node(sim, node, field, text)]
    if node.id != 0 and field == "children" and _solid_holder(sim, node):
        return _import_into_solid(sim, node, position, text, warnings)
    if field == "children" and node.type == "Robot" and not node.nested:
        return _import_into_robot(sim, node, position, text, warnings)
    if node.nested and _nested_of(sim, node).owner_kind == "Robot":
        raise ValueError(f"field {field!r} of {_what(node)}: nodes are not imported into a node inside a robot here "
                         "(a departure from Webots): import into the robot's own children")
    if node.id != 0 or field != "children":
        what = "the root" if node.id == 0 else f"{node.type} {node.name or node.id!r}"
        raise ValueError(f"field {field!r} of {what}: nodes are imported into the 'children' of the root, of a "
                         "top-level Solid and of the Poses, Transforms, Groups and Solids inside one only here")
    current = [n.id for n in root_children(sim)]
    index = insert_index(position, len(current))
    added = [node_id for _, _, node_id in sim.import_nodes(text, warnings)]
    sim.root_order = current[:index] + added + current[index:]
    return added


_RIDING = frozenset({"Pose", "Transform", "Group", "Shape", "Solid"})


def _import_into_robot(sim: Any, node: Node, position: int, text: str, warnings: list[str] | None) -> list[int]:
    """Webots' ``importMFNodeFromString`` into a robot's own ``children`` (radar_target_tracker's markers): each of
    the string's nodes (a Pose, Transform or Group of shapes, a Shape, or a Solid without boundingObject or
    physics) is imported as at the root (a solid of its shapes) and rides the robot from then on, fixed where
    its translation and rotation put it in the robot's frame (``Simulation.ride_solid``); it is listed in the
    robot's ``children`` at ``position``, its parent the robot, its ``translation``/``rotation`` in the robot's
    frame (set: moved there). One line and nothing changed for any other node (a solid with a bounding object
    would be its own robot's obstacle here)."""
    from sensorium.server.sim.imports import LABEL, ImportRefused

    doing = f"field 'children' of {_what(node)}: nothing imported"
    try:
        for part in _string_nodes(text, sim.limits):
            if not _shapes_only(part):
                raise ValueError(f"{doing}: {LABEL}:{part.line}:{part.col}: a {part.type} is not imported into a robot "
                                 "here, only a Shape, or a Pose, Transform, Group or Solid holding only shapes (no "
                                 "boundingObject, no physics): a departure from Webots")
    except ImportRefused as exc:
        raise ValueError(f"{doing}: {exc}") from None
    current = _children(sim, node)
    index = insert_index(position, len(current))
    made = sim.import_nodes(text, warnings)
    ids = [node_id for _, _, node_id in made]
    riders = sim.__dict__.setdefault("_rider_ids", {})
    for _, key, node_id in made:
        riders[node_id] = (str(node.key), str(key))
        sim.ride_solid(str(key), str(node.key), sim.scene.solid_poses[str(key)])   # (its pose as written: in the robot)
    sim.__dict__.setdefault("_robot_child_order", {})[str(node.key)] = current[:index] + ids + current[index:]
    return ids


def _shapes_only(part: Any) -> bool:
    """A node written that rides a robot here: a Shape, a Pose, Transform or Group of shapes, or a Solid of shapes
    without a boundingObject or physics (kinematic contact never makes it its own robot's obstacle)."""
    from sensorium.server.sim.imports import _only_shapes

    if part.type == "Solid" and part.proto is None and not {"boundingObject", "physics"} & part.fields.keys():
        children = part.fields.get("children", [])
        return all(_only_shapes(c) for c in (children if isinstance(children, list) else [children]))
    return part.type in _RIDING and part.type != "Solid" and _only_shapes(part)


def _string_nodes(text: str, limits: Any) -> list[Any]:
    """A node string's nodes as written (its syntax checked, within the world's limits): ``ImportRefused``."""
    from sensorium.server.sim.imports import LABEL, ImportRefused, _check_string
    from sensorium.server.world.limits import ProtoLimits
    from sensorium.server.world.wbt.parser import Parser, Tokens, WbtSyntaxError

    _check_string(text, limits)
    try:
        wbt = Parser(Tokens(text, LABEL), LABEL, limits=ProtoLimits.matching(limits)).file("R2023b", text)
    except WbtSyntaxError as exc:
        raise ImportRefused(f"{LABEL}:{exc.line}:{exc.col}: {exc.message}") from None
    return list(wbt.nodes)


def _rider(sim: Any, node: Node) -> tuple[str, str] | None:
    """(robot, solid) for a solid a Supervisor imported into that robot's children and still there; else None."""
    found = getattr(sim, "_rider_ids", {}).get(node.id) if not node.nested and not node.visual else None
    return found if found is not None and found[1] in getattr(sim, "solid_riders", {}) else None


def _rider_frame(sim: Any, n: Node) -> Any:
    rider = _rider(sim, n)
    assert rider is not None
    return sim.solid_riders[rider[1]][1]


def _set_rider(sim: Any, n: Node, field: str, value: list[float]) -> None:
    _check_pose_value(field, value)
    kwargs = {"translation": value} if field == "translation" else {"translation": None, "rotation": value}
    robot, key = _rider(sim, n)        # type: ignore[misc]
    sim.ride_solid(key, robot, moved_pose(_rider_frame(sim, n), **kwargs))


_RIDER_POSE: dict[str, tuple[str, Getter, Setter]] = {
    "translation": ("SFVec3f", lambda sim, n: [float(v) for v in _rider_frame(sim, n).translation],
                    lambda sim, n, v: _set_rider(sim, n, "translation", v)),
    "rotation": ("SFRotation", lambda sim, n: matrix_axis_angle(_rider_frame(sim, n).rotation),
                 lambda sim, n, v: _set_rider(sim, n, "rotation", v)),
}


def _robot_riders(sim: Any, robot: Node) -> list[Node]:
    """The solids riding ``robot`` that a Supervisor imported into its children, in their order there."""
    order = getattr(sim, "_robot_child_order", {}).get(robot.key, ())
    riders = getattr(sim, "_rider_ids", {})
    if not any(i in riders for i in order):        # (most robots: no walk over the world's nodes)
        return []
    by_id = {n.id: n for n in _nodes(sim)}
    return [by_id[i] for i in order if i in riders and i in by_id and _rider(sim, by_id[i]) is not None]


def _solid_holder(sim: Any, node: Node) -> bool:
    """A top-level Solid (not a robot, no imported Shape's holder) or a Pose, Transform, Group or Solid its world
    file writes inside it: a node whose ``children`` a Supervisor imports into (:func:`_import_into_solid`)."""
    if node.nested:
        n = _nested_of(sim, node)
        return n.owner_kind == "Solid" and n.type in (*_SOLID_POSES, "Solid") and bool(n.at) and n.shape is None
    return node.type == "Solid" and not node.visual and not node.scenery


def _solid_key(sim: Any, node: Node) -> tuple[str, int]:
    """The name and node id of the top-level solid ``node`` is or is inside."""
    if node.nested:
        n = _nested_of(sim, node)
        return n.owner_key, n.owner
    return str(node.key), node.id


def _import_into_solid(sim: Any, node: Node, position: int, text: str, warnings: list[str] | None) -> list[int]:
    """Webots' ``importMFNodeFromString`` into the ``children`` of a top-level Solid or of a Pose, Transform or
    Group inside one: the string's nodes written there, at ``position`` (:func:`insert_index` among the children
    written), the solid built again as its world file would build with them (sim/regenerate.py
    ``rebuild_children``, the path a Pose's set takes): from the next measurement they are part of it, seen as its
    other shapes are and moving with it. Every other node keeps its id; the new ones are Supervisor nodes like
    the solid's others (found by DEF, their fields read and their Poses' set, removable: :func:`_remove_imported`)
    until ``simulationReset`` takes them out (:func:`reset_nested_imports`). Returns the new top nodes' ids. What
    does not parse or build changes nothing (one line)."""
    from sensorium.server.sim.imports import ImportRefused
    from sensorium.server.sim.regenerate import (
        IMPORT_LINES,
        parse_nested_import,
        rebuild_children,
        written_children,
        written_node,
    )

    table = _table(sim)
    key, owner = _solid_key(sim, node)
    doing = f"field 'children' of {_what(node)}: nothing imported"
    _check_rebuildable(sim, table, owner, key, doing, "the nodes imported")
    holder_at = tuple(_nested_of(sim, node).at[:2]) if node.nested else None
    top = written_node(sim, key)
    holder = written_node(sim, key, holder_at) if holder_at else top     # type: ignore[arg-type]
    if top is None or holder is None or holder.type not in ("Solid", *_SOLID_POSES):
        raise ValueError(f"{doing}: solid {key!r} was not loaded from a .wbt world file's Solid kept here (a PROTO "
                         "instance's children are its body's, or a solid a Supervisor imported)")
    at = (holder.line, holder.col)
    serial = getattr(sim, "_nested_import_serial", 0) + 1
    try:
        nodes = parse_nested_import(sim, key, text, serial)
        index = insert_index(position, len(written_children(holder)))
        corrected: list[str] = []
        made = _rebuilt_in_place(sim, key, lambda: rebuild_children(
            sim, key, owner, at, lambda now: [*now[:index], *nodes, *now[index:]], corrected))
    except ImportRefused as exc:
        raise ValueError(f"{doing}: {_import_line(str(exc))}") from None
    if warnings is not None:
        warnings += [_import_line(w) for w in corrected]
    sim._nested_import_serial = serial
    sim.__dict__.setdefault("_nested_imports", set()).add(key)
    added = nested.regrow(sim, table, owner, key, made.model,      # (this import's lines: IMPORT_LINES)
                          fresh=lambda m: bool(m.at) and m.at[0] // IMPORT_LINES == serial)
    tops = {(n.line, n.col): n for n in nodes}
    made_tops = [i for i in added if tuple(table.get(i).at[:2]) in tops]      # type: ignore[union-attr]
    if len(made_tops) != len(nodes):          # one of them is no node here: the solid back as it was
        lost = next(n for at, n in tops.items() if all(tuple(table.get(i).at[:2]) != at for i in made_tops))  # type: ignore[union-attr]
        again = _rebuilt_in_place(sim, key, lambda: rebuild_children(
            sim, key, owner, at, lambda now: [c for c in now if all(c is not n for n in nodes)]))
        nested.regrow(sim, table, owner, key, again.model, gone=frozenset(added))
        scaled = node.nested and _nested_of(sim, node).scale not in (None, (1.0, 1.0, 1.0))
        raise ValueError(f"{doing}: node string:{lost.line % IMPORT_LINES}:{lost.col}: {lost.type} is no node " + (
            "under a scaled Transform here (only a Shape or a light is)" if scaled else
            "a solid's children hold here (a Shape, a Pose, Transform or Group, a Solid or a light)"))
    return made_tops


def _import_line(line: str) -> str:
    """An error line of a rebuild with a node string in it: the string's lines as the string numbers them."""
    import re

    from sensorium.server.sim.imports import LABEL
    from sensorium.server.sim.regenerate import IMPORT_LINES

    def back(m: re.Match[str]) -> str:
        return f"{LABEL}:{int(m.group(2)) % IMPORT_LINES}:"

    return re.sub(r"(\S+):(\d{10,}):", back, line)


def _remove_imported(sim: Any, node: Node) -> None:
    """A node a Supervisor imported inside a top-level solid removed (Webots' ``remove()``): the solid built again
    without it (its written node taken out of its parent's children), so that nothing of it stays and the solid's
    Poses stay settable; its id and those of the nodes inside it read as removed."""
    from sensorium.server.sim.imports import ImportRefused
    from sensorium.server.sim.regenerate import rebuild_children

    table = _table(sim)
    n = _nested_of(sim, node)
    key, owner = n.owner_key, n.owner
    parent = table.get(n.parent)
    holder_at = tuple(parent.at[:2]) if parent is not None else None
    if holder_at is None:
        from sensorium.server.sim.regenerate import written_node

        top = written_node(sim, key)
        assert top is not None
        holder_at = (top.line, top.col)
    gone = {n.id}
    todo = [n.id]
    while todo:
        for c in table.by_parent.get(todo.pop(), ()):
            gone.add(c.id)
            todo.append(c.id)
    mine = (n.at[0], n.at[1])
    try:
        made = _rebuilt_in_place(sim, key, lambda: rebuild_children(
            sim, key, owner, holder_at, lambda now: [c for c in now if not (
                hasattr(c, "line") and (c.line, c.col) == mine)]))
    except ImportRefused as exc:
        raise ValueError(f"{_what(node)} not removed: {_import_line(str(exc))}") from None
    for at in [a for a, (node_id, _) in getattr(sim, "_posed", {}).get(key, {}).items() if node_id in gone]:
        del sim._posed[key][at]
    nested.regrow(sim, table, owner, key, made.model, gone=frozenset(gone))


def reset_nested_imports(sim: Any) -> None:
    """After a ``simulationReset``: the nodes a Supervisor imported inside top-level solids taken out (Webots'
    reset reloads the world), each solid built again as written now without them (the other nodes' ids kept;
    the Poses set since are put back by :func:`reset_solid_poses`)."""
    from sensorium.server.sim.regenerate import imported_line, rebuild_unimported

    keys = sim.__dict__.pop("_nested_imports", set())
    if not keys:
        return
    table = _table(sim)
    for key in sorted(keys):
        posed = getattr(sim, "_posed", {}).get(key, {})
        for at in [a for a in posed if imported_line(a[0])]:
            del posed[at]
        if key not in sim.scene.solid_poses:
            continue
        owner = next(o for o, k in _solid_owners(sim) if k == key)
        gone = frozenset(m.id for m in table.by_owner.get(owner, ()) if any(
            imported_line(p.at[0]) for p in _line_of(table, m) if p.at))
        made = _rebuilt_in_place(sim, key, lambda: rebuild_unimported(sim, key, owner))   # noqa: B023
        nested.regrow(sim, table, owner, key, made.model, gone=gone)


def _line_of(table: nested.Table, n: nested.Nested) -> list[nested.Nested]:
    """``n`` and the nodes above it inside its owner."""
    out = [n]
    while True:
        up = table.get(out[-1].parent)
        if up is None:
            return out
        out.append(up)


def _solid_owners(sim: Any) -> list[tuple[int, str]]:
    return [(n.id, str(n.key)) for n in _nodes(sim) if n.type == "Solid" and not n.nested and not n.visual]


def import_sf_node(sim: Any, node: Node, field: str, text: str) -> int:
    """Webots' ``importSFNodeFromString``: into an empty ``coord`` or ``color`` of an imported line or point
    set (visuals.py: a ``Coordinate`` or ``Color`` as written, seen by no sensor, its items then set as the
    others'); returns its id. Any other SFNode field is read-only here, a full one refused as in Webots
    (one line, nothing changed)."""
    from sensorium.server.sim.imports import parse_sf_node_string

    fields = _fields(sim, node)
    entry = fields.get(field)
    if entry is None or entry[0] != "SFNode":
        kind = f" ({entry[0]})" if entry else ""
        raise ValueError(f"field {field!r}{kind} of {_what(node)}: a node string is imported into an SFNode field only")
    if not (node.visual and node.id >= visuals.FIRST_ID):
        raise ValueError(f"field {field!r} (SFNode) of {_what(node)} is read-only here: a node string is imported into "
                         "the empty coord or color of an imported line or point set only; nothing changed")
    parent = _vnode(sim, node)
    if parent.values.get(field, 0) or not (parent.inert and field in visuals.SF_SLOTS.get(parent.type, {})):
        return _visuals(sim).attach(parent, field, None)       # its line: full, or not a slot served here
    return _visuals(sim).attach(parent, field, parse_sf_node_string(text, sim.limits))


def _import(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    corrected: list[str] = []
    try:                         # ImportRefused is a ValueError: one line, nothing changed
        added = import_nodes(sim, node_by_id(sim, a.node), a.field, a.position, a.node_string, corrected)
        return {"value": added, LOG: corrected}
    except (KeyError, OSError, RecursionError) as exc:     # never a traceback for a controller's string
        raise ValueError(f"the node string cannot be imported: {exc}") from None


LOG = "log"
"""A handler's reply may carry lines for the server's log under this key (the core logs and drops
them): what Webots would print in its console, e.g. an imported node's corrected values."""


def _reset(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    sim.reset()
    reset_nested_imports(sim)
    reset_solid_poses(sim)
    return {"success": True}


def _reset_physics(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    """Webots' ``resetPhysics``: the velocities of the node and the Solids under it zeroed. The ones that
    have a velocity here of their own are the top-level solids falling (sim/falling.py): the root's
    reset (``simulationResetPhysics``) stops them all, a top-level solid's itself; a robot keeps its
    motors' commands (Webots), and nothing inside a robot or solid moves by itself."""
    node = node_by_id(sim, a.node)
    if node is ROOT:
        sim.reset_physics()
    elif node.type == "Solid" and not (node.nested or node.visual or node.scenery):
        sim.reset_physics(str(node.key))
    return {"success": True}


def _set_mode(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    ls.set_mode(MODES[a.mode])
    return {"success": True}


def _labels(sim: Any) -> viewshot.Labels:
    return _kept(sim, "_labels", viewshot.Labels)


def _set_label(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    _labels(sim).set(a.id, a.text, a.x, a.y, a.size, a.color, a.transparency, a.font)
    return {"success": True}


def remove_sf(sim: Any, node: Node, field: str, level: int = -1) -> None:
    """Webots' ``removeSF``: the node in an SFNode field taken out, the field NULL. Served on the ``coord`` and
    ``color`` of an imported line or point set (what ``importSFNodeFromString`` fills: the set then draws
    nothing until a node is imported again); an empty field is left as it is (Webots); any other SFNode field
    is read-only here (one line, nothing changed)."""
    level = _level(node, level)
    fields = _fields(sim, node, level)
    entry = fields.get(field)
    if entry is None or entry[0] != "SFNode":
        kind = f" ({entry[0]})" if entry else ""
        raise ValueError(f"field {field!r}{kind} of {_what(node)}: removeSF takes an SFNode field")
    if not entry[1](sim, node):
        return
    if not (node.visual and node.id >= visuals.FIRST_ID):
        raise ValueError(f"field {field!r} (SFNode) of {_what(node)} is read-only here: removeSF takes the node out of "
                         "the coord or color of an imported line or point set only; nothing changed")
    _visuals(sim).detach(_vnode(sim, node), field)


def _remove_sf(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    remove_sf(sim, node_by_id(sim, a.node), a.field, a.level)
    return {"success": True}


def _export_string(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    from sensorium.server.daemon.export import node_string  # (export.py reads this module's nodes)

    return {"value": node_string(sim, node_by_id(sim, a.node))}


def _world_save(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    """The world as .wbt text; the client writes the file (the server never writes a path a client names)."""
    from sensorium.server.daemon.export import world_string

    return {"value": world_string(sim)}


def _export_image(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    """The Viewpoint's picture (``viewshot.EXPORT_SIZE``) with the labels: pixels only, the client
    encodes and writes the file (the server never writes a path a client names)."""
    w, h = viewshot.EXPORT_SIZE
    rgb = viewshot.picture(sim, w, h, _labels(sim))
    return {"width": w, "height": h, "data": rgb.tobytes()}


def _movie_start(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    """A movie's frames rendered from now on (the client runs the encoder and writes the file)."""
    movie = getattr(sim, "_movie", None)
    if movie is not None:
        raise ValueError(f"a movie is already being recorded (by robot {movie.robot!r}): stop it first")
    movie = viewshot.Movie(robot, sim.time_ms, sim.basic_time_step, a.width, a.height, a.acceleration, a.caption)
    viewshot.viewpoint_of(sim)       # a Viewpoint that makes no picture: said now, not at the first frame
    sim._movie = movie
    return {"step_ms": movie.step_ms}


def _own_movie(sim: Any, robot: str) -> Any:
    movie = getattr(sim, "_movie", None)
    if movie is None or movie.robot != robot:
        raise ValueError("no movie is being recorded by this robot")
    return movie


def _movie_frames(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    movie = _own_movie(sim, robot)
    frames, more = movie.take()
    return {"frames": frames, "more": more, "width": movie.width, "height": movie.height, "full": movie.full,
            "failed": movie.failed}


def _movie_stop(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    """The movie ends; frames not yet taken are dropped (the client takes them first)."""
    movie = _own_movie(sim, robot)
    sim._movie = None
    return {"value": movie.frames}


def movie_after_step(sim: Any) -> None:
    """The daemon's call after each basic step: a recording movie's frame when it is due."""
    movie = sim._movie
    movie.after_step(sim, getattr(sim, "_labels", None))


def movie_released(sim: Any, robot: str) -> None:
    """A robot's controller went: its movie ends."""
    movie = getattr(sim, "_movie", None)
    if movie is not None and movie.robot == robot:
        sim._movie = None


HANDLERS = {
    "get_from_def": lambda sim, ls, robot, a: node_ref(sim, find_node(sim, a.name)),
    "get_from_proto_def": _from_proto_def,
    "get_self": lambda sim, ls, robot, a: node_ref(sim, robot_node(sim, robot)),
    "get_from_device": lambda sim, ls, robot, a: node_ref(sim, device_node(sim, robot, a.device)),
    "get_root": lambda sim, ls, robot, a: node_ref(sim, ROOT),
    "get_from_id": lambda sim, ls, robot, a: node_ref(sim, node_from_id(sim, a.id)),
    "get_field": lambda sim, ls, robot, a: get_field(sim, node_by_id(sim, a.node), a.field, a.level),
    "get_proto": lambda sim, ls, robot, a: get_proto(sim, node_by_id(sim, a.node), a.level),
    "set_visibility": _set_visibility,
    "move_viewpoint": _move_viewpoint,
    "get_actual_field": lambda sim, ls, robot, a: {"value": actual_field(sim, node_by_id(sim, a.node), a.field,
                                                                         a.level)},
    "set_field": _set_field,
    "get_node_pose": lambda sim, ls, robot, a: node_pose(sim, node_by_id(sim, a.node)),
    "get_node_velocity": lambda sim, ls, robot, a: {"value": node_velocity(sim, node_by_id(sim, a.node))},
    "get_node_center_of_mass": lambda sim, ls, robot, a: {"value": center_of_mass(sim, node_by_id(sim, a.node))},
    "get_node_static_balance": lambda sim, ls, robot, a: {"value": static_balance(sim, node_by_id(sim, a.node))},
    "get_node_contact_points": lambda sim, ls, robot, a: contact_points(sim, node_by_id(sim, a.node), a.include_descendants),
    "remove_node": _remove,
    "set_joint_position": _set_joint_position,
    "save_node_state": _save_state,
    "load_node_state": _load_state,
    "import_node_from_string": _import,
    "simulation_reset": _reset,
    "reset_physics": _reset_physics,
    "simulation_set_mode": _set_mode,
    "simulation_get_mode": lambda sim, ls, robot, a: {"value": MODES.index(ls.mode)},
    "set_label": _set_label,
    "export_image": _export_image,
    "movie_start": _movie_start,
    "movie_frames": _movie_frames,
    "movie_stop": _movie_stop,
    "node_export_string": _export_string,
    "world_save": _world_save,
    "field_remove_sf": _remove_sf,
}
