"""exportString, worldSave and removeSF (tests/test_supervisor_export.py on tests/worlds/export_world.wbt): the box
moved and exported, its text imported again as a second box, the world saved where $EXPORT_SAVE names (without a
filename and without .wbt: one line each, False), an imported point set's coord taken out with removeSF and filled
again, the robot's distance sensor exported; removeSF on a field not served is one line. The same
stdout as tests/c/supervisor_export.c."""

import os

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
box = robot.getFromDef("BOX")
box.getField("translation").setSFVec3f([1.0, 0.0, 0.1])
box.getField("rotation").setSFRotation([0.0, 0.0, 1.0, 0.0])
text = box.exportString()
print(text)
children = robot.getRoot().getField("children")
children.importMFNodeFromString(-1, text)
clone = children.getMFNode(-1)
print("clone", clone.getDef(), clone.getField("name").getSFString(), " ".join(f"{v:g}" for v in clone.getPosition()))
print("save", int(robot.worldSave()), int(robot.worldSave("saved.txt")), int(robot.worldSave(os.environ["EXPORT_SAVE"])))
children.importMFNodeFromString(-1, "DEF DOTS Shape { appearance Appearance { } geometry DEF SET PointSet { coord "
                               "Coordinate { point [ 1 2 3 ] } } }")
coord = robot.getFromDef("SET").getField("coord")
coord.removeSF()
print("removed", int(coord.getSFNode() is None))
coord.removeSF()                                                      # empty: nothing (no line)
coord.importSFNodeFromString("Coordinate { point [ 4 5 6, 7 8 9 ] }")
print("again", coord.getSFNode().getField("point").getCount())
robot.getFromDef("DOTS").getField("appearance").removeSF()           # not served: one line
box.getField("translation").removeSF()                                # wrong type: Webots' line
print("inside", robot.getFromDevice(robot.getDevice("ds")).exportString().split("\n")[0])   # its first line
robot.step(step)
