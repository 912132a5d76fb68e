"""A Webots-style supervisor asking getActualField (tests/test_supervisor_actual_field.py on
tests/worlds/proto/supervisor_proto_fields.wbt): a PROTO instance's base-node field and a field of the PROTO
it is built on lead to the interface field that sets them, a field no interface field reaches to None, a
node's own field to itself; setting the actual field changes the base-node field. Prints one line per
answer, as tests/c/supervisor_actual_field.c does."""

from controller import Supervisor


def name(field) -> str:
    return "NULL" if field is None else field.getName()


robot = Supervisor()
robot.step(int(robot.getBasicTimeStep()))
big = robot.getFromDef("BIG")                       # BigCrate, built on Crate, built on Solid
own = big.getField("translation")
base = big.getBaseNodeField("translation")
actual = base.getActualField()
print("base translation", name(actual), int(actual == own))
parent = big.getProto().getParent()                 # Crate, as BigCrate's body gives it
print("crate translation", name(parent.getField("translation").getActualField()),
      int(parent.getField("translation").getActualField() == own))
print("crate size", name(parent.getField("size").getActualField()))        # a constant of BigCrate's body
print("own translation", int(own.getActualField() == own))
actual.setSFVec3f([3.0, -0.5, 0.2])
print("base after set", " ".join(f"{x:.17g}" for x in base.getSFVec3f()))
box = robot.getFromDef("BOX")                       # a base Solid: its fields are its own
print("box translation", int(box.getBaseNodeField("translation").getActualField() == box.getField("translation")))
print("keeper children", name(robot.getSelf().getBaseNodeField("children").getActualField()))
