"""A Webots-style supervisor reading PROTO instances' own fields (tests/test_supervisor_proto_fields.py on
tests/worlds/proto/supervisor_proto_fields.wbt): its own PROTO's interface through getField, getProto and
getFieldByIndex, its base node's fields, a PROTO built on another (getParent), a PROTO inside it, and a
PROTO field set through IS, and one that builds the crate again. Written as for Webots; prints one line per reading, as
tests/c/supervisor_proto_fields.c does."""

from controller import Supervisor


def g(x: float) -> str:
    return f"{x:.17g}"


def gs(xs) -> str:
    return " ".join(g(x) for x in xs)


robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.step(timestep)
me = robot.getSelf()
proto = me.getProto()
print("proto", proto.getTypeName(), int(proto.isDerived()), proto.getNumberOfFields())
print("node_count", me.getNumberOfFields())
reach = me.getField("reach")
print("reach", reach.getTypeName(), g(reach.getSFFloat()))
print("level", me.getField("level").getSFInt32())
print("active", int(me.getField("active").getSFBool()))
print("footprint", gs(me.getField("footprint").getSFVec2f()))
print("color", gs(me.getField("color").getSFColor()))
gains = me.getField("gains")
print("gains", gains.getCount(), gs([gains.getMFFloat(0), gains.getMFFloat(1)]))
waypoints = me.getField("waypoints")
print("waypoints", waypoints.getCount(), gs(waypoints.getMFVec3f(-1)))
tags = me.getField("tags")
print("tags", tags.getCount(), tags.getMFString(0))
ids = me.getField("ids")
print("ids", ids.getCount(), ids.getMFInt32(0), ids.getMFInt32(1))
flags = me.getField("flags")
print("flags", flags.getCount(), int(flags.getMFBool(0)), int(flags.getMFBool(1)))
print("slot", me.getField("bodySlot").getTypeName(), me.getField("bodySlot").getCount())   # not served: a line
print("byindex", me.getFieldByIndex(3).getName(), proto.getFieldByIndex(13).getTypeName())
print("base", me.getBaseNodeField("controller").getSFString(), int(me.getBaseNodeField("supervisor").getSFBool()))
print("none", "null" if me.getField("controller") is None else "field")
big = robot.getFromDef("BIG").getProto()
print("big", big.getTypeName(), int(big.isDerived()), big.getNumberOfFields())
parent = big.getParent()
print("parent", parent.getTypeName(), int(parent.isDerived()), parent.getNumberOfFields(),
      gs(parent.getField("size").getSFVec3f()))
print("grand", "null" if parent.getParent() is None else "proto")
print("crate", gs(robot.getFromDef("CRATE").getField("size").getSFVec3f()))
print("box", "null" if robot.getFromDef("BOX").getProto() is None else "proto")
tag = robot.getFromDef("TAG")
print("tag", tag.getTypeName(), g(tag.getField("weight").getSFFloat()), gs(tag.getField("translation").getSFVec3f()))
crate = robot.getFromDef("CRATE")
crate.getField("translation").setSFVec3f([1.5, 0.0, 0.1])
crate.getField("size").setSFVec3f([1.0, 1.0, 1.0])          # the crate is built again, where it was moved
robot.step(timestep)
print("set", gs(crate.getBaseNodeField("translation").getSFVec3f()), gs(crate.getField("size").getSFVec3f()))
