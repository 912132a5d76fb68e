"""getFromProtoDef (tests/test_supervisor_proto_def.py on tests/worlds/proto/supervisor_proto_def.wbt): the nodes
of a PROTO instance's body found by their DEF and read as any node, the scope of a nested PROTO instance, the
NULLs. The same stdout as tests/c/supervisor_proto_def.c."""

from controller import Supervisor

robot = Supervisor()
robot.step(int(robot.getBasicTimeStep()))
rover = robot.getSelf()
shelf = robot.getFromDef("SHELF")
box = robot.getFromDef("BOX")


def g(values) -> str:
    return " ".join(f"{v:g}" for v in values)


def same(a, b) -> int:
    return int(a is not None and b is not None and a.getId() == b.getId())


chassis = rover.getFromProtoDef("CHASSIS")
print("chassis", chassis.getTypeName(), same(chassis.getParentNode(), rover), g(chassis.getField("translation").getSFVec3f()))
shape = rover.getFromProtoDef("HULL_SHAPE")        # the DEF'd Shape, not its USE under TOP
print("shape", shape.getTypeName(), same(shape.getParentNode(), chassis))
paint = rover.getFromProtoDef("PAINT")
print("paint", paint.getTypeName(), g(paint.getField("baseColor").getSFColor()), g([paint.getField("roughness").getSFFloat()]))
hull = rover.getFromProtoDef("HULL")
print("hull", hull.getTypeName(), g(hull.getField("size").getSFVec3f()))
eye = rover.getFromProtoDef("EYE")
print("eye", eye.getTypeName(), eye.getField("name").getSFString(), g(eye.getPosition()))
arm = rover.getFromProtoDef("ARM")                 # a nested PROTO instance written in Rover's body
print("arm", arm.getTypeName(), arm.getBaseTypeName(), int(arm.isProto()))
tool = rover.getFromProtoDef("TOOL")               # written in Rover's body, held by Arm's slot
print("tool", tool.getField("name").getSFString(), g(tool.getPosition()), same(tool, arm.getFromProtoDef("TOOL")))
# Arm's own body is Arm's scope, not Rover's
print("elbow", int(rover.getFromProtoDef("ELBOW") is None), arm.getFromProtoDef("ELBOW").getTypeName(),
      arm.getFromProtoDef("GRIP").getField("name").getSFString(), int(arm.getFromProtoDef("CHASSIS") is None))
print("given", same(rover.getFromProtoDef("GIVEN"), robot.getFromDef("GIVEN")))
top = rover.getFromProtoDef("TOP")
copy = top.getField("children").getMFNode(0)       # the USE of HULL_SHAPE: a node of its own, no DEF
print("top", top.getTypeName(), copy.getTypeName(), same(copy, shape), same(copy.getParentNode(), top))
# NULLs: no such DEF (no line), physics-only and bounding nodes (a line each), no PROTO instance, an empty DEF
print("none", int(rover.getFromProtoDef("NOPE") is None), int(rover.getFromProtoDef("MASS") is None),
      int(rover.getFromProtoDef("BOUND") is None), int(rover.getFromProtoDef("ROVER") is None),
      int(box.getFromProtoDef("INSIDE") is None), int(rover.getFromProtoDef("") is None))
board = shelf.getFromProtoDef("BOARD")
print("board", board.getTypeName(), board.getField("name").getSFString(), g(board.getPosition()))
print("leg", shelf.getFromProtoDef("LEG").getTypeName(), g(shelf.getFromProtoDef("WOOD").getField("diffuseColor").getSFColor()))
bulb = shelf.getFromProtoDef("BULB")      # a light of the body: a node, under the shelf
print("bulb", bulb.getTypeName(), same(bulb.getParentNode(), shelf), g(bulb.getField("location").getSFVec3f()))
