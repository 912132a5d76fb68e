"""The root's ``children`` of a world: its top-level nodes in file order, as Webots loads them.

Webots adds a world file's top-level nodes to the root in file order and then makes sure a
``WorldInfo`` (at index 0) and a ``Viewpoint`` (at index 1) exist, adding a default one where the
file has none. A ``.wbt`` world records its top-level nodes (``World.top_nodes``); a YAML or JSON
world has none recorded: its root holds a default ``WorldInfo`` and ``Viewpoint``, then its robots,
solids and lights in the lists' order. Nodes Sensorium does not simulate ("scenery": ``WorldInfo``,
``Viewpoint``, ``Background``, ...) keep their type and DEF name (and a Viewpoint's or Background's
written values). A top-level Group, Pose or Transform (not a PROTO instance) holding robots, solids or
lights is a node of its own there, as in Webots: its members (what it became, in file order; a
group nested in it is flattened into it) are its ``children`` and no longer the root's. A PROTO instance keeps its PROTO's name: a scenery node's, and a robot's, solid's
or light's when the top-level node became that node alone (a PROTO whose base is a Group holding
several solids names none of them).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from sensorium.schemas import world as wm

KINDS = ("robots", "solids", "lights")
GROUPS = ("Group", "Pose", "Transform")    # the top-level groups served as nodes holding what they became


# the base types a simulated node of each kind has (a PROTO instance of another base is not named after it):
# a top-level solid here is a Solid or another of Webots' Solid nodes the converter keeps as one (a
# Charger, a Fluid, a device or a Track outside any robot: Webots' ratslife feeder is a Charger PROTO)
SOLID_BASES = ("Solid", "Charger", "Fluid", "Track", "DistanceSensor", "LightSensor", "Lidar", "PositionSensor", "LED",
               "RangeFinder", "Camera", "Display", "Speaker", "Microphone", "Emitter", "Receiver", "GPS", "Compass",
               "Accelerometer", "Gyro", "InertialUnit", "TouchSensor", "Pen", "Connector", "Radar", "Altimeter",
               "VacuumGripper", "Radio", "Skin")
BASES = {"robots": ("Robot",), "solids": SOLID_BASES, "lights": ("PointLight", "SpotLight", "DirectionalLight")}


@dataclass(frozen=True, slots=True)
class Scenery:
    type: str
    def_name: str      # "" without one
    proto: str = ""    # the PROTO it is an instance of ("" for a base node)
    fields: dict = field(default_factory=dict)   # a Viewpoint's or Background's written values (TopNode.fields)
    interface: tuple = ()   # a PROTO instance's interface (TopNode.interface: wm.ProtoLevel each)
    members: tuple[tuple[str, int], ...] = ()   # a group's: the (kind, index) of each node it holds, in order


@dataclass(frozen=True, slots=True)
class TopLevel:
    order: tuple[tuple[str, int], ...]   # ("robots" | "solids" | "lights" | "scenery", index) in root order
    scenery: tuple[Scenery, ...]         # by index: file order, then the defaults Webots adds
    protos: dict = field(default_factory=dict)   # (kind, index) -> the PROTO a robot, solid or light is an
                                                 # instance of (the top-level node it alone became)
    interfaces: dict = field(default_factory=dict)   # (kind, index) -> that instance's interface (wm.ProtoLevel each)
    written: dict = field(default_factory=dict)   # (kind, index) -> the place in file order of the top-level node it
                                                  # came from (a group: ("scenery", index)); a Supervisor's
                                                  # exportString writes that node (daemon/export.py)


def top_level(world: wm.World) -> TopLevel:
    sizes = {k: len(getattr(world, k)) for k in KINDS}
    used = dict.fromkeys(KINDS, 0)
    order: list[tuple[str, int]] = []
    scenery: list[Scenery] = []
    protos: dict[tuple[str, int], str] = {}
    interfaces: dict[tuple[str, int], tuple] = {}
    written: dict[tuple[str, int], int] = {}
    for at, node in enumerate(world.top_nodes):
        counts = {"robots": node.robots, "solids": node.solids, "lights": node.lights}
        if not any(counts.values()):
            written[("scenery", len(scenery))] = at
            order.append(("scenery", len(scenery)))
            scenery.append(Scenery(node.type, node.def_name or "", node.proto or "", dict(node.fields),
                                   tuple(node.interface)))
            continue
        marker = counts["solids"] == 1 and not counts["robots"] and not counts["lights"] and node.def_name and \
            used["solids"] < sizes["solids"] and world.solids[used["solids"]].def_name == node.def_name
        if node.type in GROUPS and not node.proto and not marker:   # (a DEF Pose of shapes became that solid)
            members = []
            for kind in KINDS:
                take = min(counts[kind], sizes[kind] - used[kind])
                members += [(kind, used[kind] + i) for i in range(take)]
                used[kind] += take
            written[("scenery", len(scenery))] = at
            order.append(("scenery", len(scenery)))
            scenery.append(Scenery(node.type, node.def_name or "", "", dict(node.fields), (), tuple(members)))
            continue
        alone = [kind for kind in KINDS if counts[kind]]
        if node.proto and sum(counts.values()) == 1 and node.type in BASES[alone[0]] \
                and used[alone[0]] < sizes[alone[0]]:
            protos[(alone[0], used[alone[0]])] = node.proto
            interfaces[(alone[0], used[alone[0]])] = tuple(node.interface)
        for kind in KINDS:
            for _ in range(counts[kind]):
                if used[kind] < sizes[kind]:
                    written[(kind, used[kind])] = at
                    order.append((kind, used[kind]))
                    used[kind] += 1
    for kind in KINDS:        # what no top-level node accounts for (a YAML world; shapes outside any solid)
        order += [(kind, i) for i in range(used[kind], sizes[kind])]
    for place, kind in ((0, "WorldInfo"), (1, "Viewpoint")):      # Webots adds the missing mandatory nodes
        if not any(s.type == kind for s in scenery):
            order.insert(min(place, len(order)), ("scenery", len(scenery)))
            scenery.append(Scenery(kind, ""))
    return TopLevel(tuple(order), tuple(scenery), protos, interfaces, written)
