"""Hostile and careless calls on PROTO fields (tests/test_supervisor_proto_fields.py on
tests/worlds/proto/supervisor_proto_harden.wbt), the sequence of tests/c/supervisor_proto_harden.c with
the same stdout (but C's line of a field ref the library never gave): NULL and foreign refs (None, a
PROTO ref the library never gave), indexes out of range both
ways, the wrong getter for each type, names empty, long and huge, non-finite values set through IS."""

import math

from controller import Supervisor
from controller.supervisor import Field, Proto

from sensorium.client import wb

LONG_NAME = "aVeryLongParameterNameThatGoesOnAndOnPastTheSixtyFourCharactersOfOrdinaryFieldNamesX"
INT_MAX, INT_MIN = (1 << 31) - 1, -(1 << 31)


def g(x: float) -> str:
    return f"{x:.17g}"


def numbers(what: str, v, n: int) -> None:
    shown = [g(x) for x in (v if v is not None else [-999.0] * n)]
    print(" ".join([what, *shown]) + ("" if v is not None else " null"))


def null(x) -> int:
    return int(x is None)


robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
me = robot.getSelf()
lengthy = robot.getFromDef("LONG")
box = robot.getFromDef("BOX")
proto = lengthy.getProto()
foreign = Proto((lengthy._ref, 9))               # not a ref the library gave

print("nullnode", null(wb.wb_supervisor_node_get_proto(None)))
nothing = Proto(None)
print(f"nullproto [{nothing.getTypeName()}] {int(nothing.isDerived())} {nothing.getNumberOfFields()} "
      f"{null(nothing.getParent())} {null(nothing.getField('translation'))} {null(nothing.getFieldByIndex(0))}")
print(f"foreign [{foreign.getTypeName()}] {foreign.getNumberOfFields()} {null(foreign.getField('translation'))}")
for bogus in ((lengthy._ref, 0), (lengthy._ref, 17), (lengthy._ref, -1), ("x", 1), (1 << 70, 1), (lengthy._ref,)):
    Proto(bogus).getTypeName()                    # one line each, nothing asked (the test counts them)
nofield = Field(None)
print("nullfield", nofield.getCount(), nofield.getMFInt32(0), g(nofield.getMFFloat(0)), null(nofield.getSFVec2f()))
print("basenull", null(wb.wb_supervisor_node_get_base_node_field(None, "name")),
      wb.wb_supervisor_node_get_number_of_fields(None))

n = proto.getNumberOfFields()
print("proto", proto.getTypeName(), n)
for bad in (-1, n, INT_MAX, INT_MIN):
    print("index", bad, null(proto.getFieldByIndex(bad)), null(lengthy.getFieldByIndex(bad)))
print("last", proto.getFieldByIndex(n - 1).getName())

huge = "x" * 100000
print("names", null(wb.wb_supervisor_node_get_field(lengthy._ref, None)), null(lengthy.getField("")),
      null(proto.getField(huge)), null(lengthy.getBaseNodeField(huge)))
longest = lengthy.getField(LONG_NAME)
print("long", longest.getTypeName(), g(longest.getSFFloat()), g(proto.getField(LONG_NAME).getSFFloat()))
print("unknown", null(lengthy.getField("nosuchfield")))

none = lengthy.getField("none")
corners = lengthy.getField("corners")
turns = lengthy.getField("turns")
size2 = lengthy.getField("size2")
label = lengthy.getField("label")
print("none", none.getCount(), g(none.getMFFloat(0)))
for what, index in (("corner0", 0), ("corner-1", -1), ("corner-2", -2), ("corner-3", -3), ("corner2", 2),
                    ("cornermin", INT_MIN)):
    numbers(what, corners.getMFVec2f(index), 2)
numbers("turn", turns.getMFRotation(0), 4)
numbers("size2", size2.getSFVec2f(), 2)
print(f"label [{label.getSFString()}] {label.getCount()}")

print(f"wrong {g(corners.getMFFloat(0))} {corners.getMFInt32(0)} {int(none.getMFBool(0))} "
      f"{null(corners.getMFVec3f(0))} {null(turns.getMFVec2f(0))} {null(size2.getMFRotation(0))} "
      f"{null(corners.getSFVec2f())} [{label.getMFString(0)}] {null(none.getMFColor(0))}")

move = lengthy.getField("translation")
move.setSFVec3f([math.nan, 0.0, 0.0])
move.setSFVec3f([0.0, math.inf, 0.0])
move.setSFVec3f([1e300, 0.0, 0.0])
move.setSFVec3f(None)
longest.setSFFloat(math.nan)
longest.setSFFloat(2.0)
robot.step(step)
numbers("moved", move.getSFVec3f(), 3)
move.setSFVec3f([0.25, -0.5, 0.1])
robot.step(step)
numbers("moved", lengthy.getBaseNodeField("translation").getSFVec3f(), 3)
print("kept", g(longest.getSFFloat()))

parent = robot.getFromDef("BIG").getProto().getParent()
print("parent", parent.getTypeName(), null(parent.getFieldByIndex(3)))
print("box", null(box.getProto()), box.getNumberOfFields(), null(box.getFieldByIndex(0)))
print("me", me.getNumberOfFields())
