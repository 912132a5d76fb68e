"""A Webots-style supervisor walking a top-level DEF Pose of solids (tests/worlds/top_groups.wbt), as
Webots' robotbenchmark referees walk their DEF Groups of obstacles. Prints one JSON line."""

import json

from controller import Node, Supervisor

robot = Supervisor()
robot.step(int(robot.getBasicTimeStep()))
trio = robot.getFromDef("TRIO")
children = trio.getField("children")
items = [children.getMFNode(i) for i in range(children.getCount())]
print(json.dumps({
    "group": [trio.getType() == Node.POSE, trio.getTypeName(), trio.getDef()],
    "count": children.getCount(),
    "positions": [n.getPosition() for n in items],
    "same": items[1].getId() == robot.getFromDef("MID").getId() == robot.getFromDef("TRIO.MID").getId(),
    "translation": trio.getField("translation").getSFVec3f(),
    "trio_position": trio.getPosition(),
}))
