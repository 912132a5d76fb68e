"""A Webots-style supervisor walking the root's children (tests/test_supervisor_root.py on
tests/worlds/root_children.wbt), as Webots' own samples do: the first child is WorldInfo, its
gravity read; then an import at a position. Written as for Webots; prints one JSON line."""

import json

from controller import Node, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
children = robot.getRoot().getField("children")


def walk() -> list:
    nodes = [children.getMFNode(i) for i in range(children.getCount())]
    return [[n.getTypeName(), n.getDef()] for n in nodes]


robot.step(timestep)
before = walk()
info = children.getMFNode(0)
world_info = [info.getType() == Node.WORLD_INFO, info.getField("gravity").getSFFloat(),
              info.getField("basicTimeStep").getSFFloat(), info.getField("title").getSFString(),
              info.getField("gpsCoordinateSystem").getSFString(), info.getField("gpsReference").getSFVec3f(),
              info.getField("coordinateSystem").getSFString()]
view = children.getMFNode(1)
no_value = [view.getField("position").getSFVec3f(), view.getPosition()[0] != view.getPosition()[0]]   # NaN
children.importMFNodeFromString(3, 'DEF BALL Solid { name "ball" }')       # after the Background
children.importMFNodeFromString(-2, "DEF SPARK PointLight { }")             # before the last
robot.step(timestep)
imported = walk()
robot.getFromDef("BALL").remove()
robot.getFromDef("SPARK").remove()
robot.step(timestep)
print(json.dumps({"before": before, "world_info": world_info, "no_value": no_value, "imported": imported,
                  "removed": walk()}), flush=True)
