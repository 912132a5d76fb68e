"""Fields by index (tests/test_supervisor_field_index.py on tests/worlds/proto/supervisor_proto_harden.wbt): a base
node's getNumberOfFields/getFieldByIndex and any node's getNumberOfBaseNodeFields/getBaseNodeFieldByIndex list
the fields served here in Webots' declaration order. The same stdout as tests/c/supervisor_field_index.c."""

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
keeper = robot.getSelf()
box = robot.getFromDef("BOX")
info = robot.getRoot().getField("children").getMFNode(0)


def names(node, base: bool) -> str:
    n = node.getNumberOfBaseNodeFields() if base else node.getNumberOfFields()
    got = [node.getBaseNodeFieldByIndex(i) if base else node.getFieldByIndex(i) for i in range(n)]
    return " ".join([str(n), *(f.getName() for f in got)])


print("box", names(box, False))
print("boxbase", names(box, True))
print("info", names(info, False))
print("keeper", keeper.getNumberOfFields(), names(keeper, True))
controller = keeper.getBaseNodeFieldByIndex(6)
print("controller", controller.getTypeName(), controller.getSFString())
print("translation", " ".join(f"{v:g}" for v in box.getFieldByIndex(0).getSFVec3f()))
print("bad", int(box.getFieldByIndex(6) is None), int(box.getBaseNodeFieldByIndex(-1) is None))
# getFromProtoDef: Keeper's body has no DEF BODY (NULL, no line); a base node is no PROTO; an empty DEF (lines)
print("protodef", int(keeper.getFromProtoDef("BODY") is None), int(keeper.getFromProtoDef("BODY") is None),
      int(box.getFromProtoDef("BODY") is None), int(keeper.getFromProtoDef("") is None))
