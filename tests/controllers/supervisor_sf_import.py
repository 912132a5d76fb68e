"""importSFNodeFromString (tests/test_supervisor_sf_import.py on tests/worlds/visual_trail.wbt): an imported
PointSet without points gets its Coordinate and Color from node strings, then its points are edited as any
line or point set's; a full slot, a node of the wrong type, a field not served and a string that does not read
are one line each, nothing changed. The same stdout as tests/c/supervisor_sf_import.c."""

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
robot.getRoot().getField("children").importMFNodeFromString(-1, "DEF DOTS Shape { geometry DEF DOT_SET PointSet { } }")
dots = robot.getFromDef("DOT_SET")
coord, color = dots.getField("coord"), dots.getField("color")
print("empty", int(coord.getSFNode() is None), int(color.getSFNode() is None))
coord.importSFNodeFromString("DEF DOT_POINTS Coordinate { point [ 1 2 3, 4 5 6 ] }")
points_node = coord.getSFNode()
points = points_node.getField("point")
points.insertMFVec3f(-1, [7.0, 8.0, 9.0])
print("coord", points_node.getTypeName(), points_node.getDef(), int(robot.getFromDef("DOT_POINTS") == points_node),
      int(points_node.getParentNode() == dots), points.getCount(), " ".join(f"{v:g}" for v in points.getMFVec3f(-1)))
coord.importSFNodeFromString("Coordinate { }")                        # full: one line
color.importSFNodeFromString("Coordinate { }")                        # the wrong node type: one line
robot.getFromDef("DOTS").getField("appearance").importSFNodeFromString("Appearance { }")   # not served: one line
color.importSFNodeFromString("Color { color [ 1 0")                   # does not read: one line
color.importSFNodeFromString("Color { color [ 1 0 0.5 ] }")
print("color", color.getSFNode().getTypeName(), " ".join(f"{v:g}" for v in color.getSFNode().getField("color").getMFColor(0)),
      points.getCount())
