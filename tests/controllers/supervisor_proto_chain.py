"""Walks the PROTO chain of the node DEF DEEP with getProto() and getParent() until it ends, one line per
PROTO (name, isDerived, its fields), as tests/c/supervisor_proto_chain.c (tests/test_supervisor_proto_fields.py)."""

from controller import Supervisor

robot = Supervisor()
robot.step(int(robot.getBasicTimeStep()))
proto = robot.getFromDef("DEEP").getProto()
while proto is not None:
    print(proto.getTypeName(), int(proto.isDerived()), proto.getNumberOfFields())
    proto = proto.getParent()
print("end")
