"""Webots' item setters and inserters of every MF type a Supervisor may call (tests/test_supervisor_mf_items.py on
tests/worlds/proto/supervisor_proto_harden.wbt): on the robot's PROTO fields (read-only here) each call gets the
server's read-only line and nothing changes; on the top-level solid Lengthy's the items change (it is built
again); the clients' own checks (a zero rotation axis, NaN, the wrong type) answer Webots' lines without a
request. The same stdout as tests/c/supervisor_mf_items.c."""

import math

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
keeper = robot.getSelf()
lengthy = robot.getFromDef("LONG")
gains, tags, flags = keeper.getField("gains"), keeper.getField("tags"), keeper.getField("flags")
corners, turns = lengthy.getField("corners"), lengthy.getField("turns")

gains.setMFFloat(0, 9.0)
gains.insertMFFloat(-1, 9.0)
tags.setMFString(0, "z")
tags.insertMFString(0, "z")
flags.setMFBool(1, True)
flags.insertMFBool(0, False)
corners.setMFVec2f(0, [3.0, 4.0])
corners.insertMFVec2f(-1, [3.0, 4.0])
turns.setMFRotation(0, [1.0, 0.0, 0.0, 0.5])
turns.insertMFRotation(0, [1.0, 0.0, 0.0, 0.5])
turns.setMFRotation(0, [0.0, 0.0, 0.0, 0.5])            # a zero axis: the client's line, no request
gains.setMFFloat(0, math.nan)                           # NaN: the client's line
gains.setMFBool(0, True)                                # the wrong type: Webots' line
print("counts", gains.getCount(), tags.getCount(), flags.getCount(), corners.getCount(), turns.getCount())
print("values", " ".join(f"{v:g}" for v in (gains.getMFFloat(0), gains.getMFFloat(1))), tags.getMFString(0),
      int(flags.getMFBool(0)), int(flags.getMFBool(1)), " ".join(f"{v:g}" for v in corners.getMFVec2f(0)),
      " ".join(f"{v:g}" for v in turns.getMFRotation(0)))
keeper.getField("level").setSFInt32(4)                  # the robot's: read-only here (Lengthy's: built again)
lengthy.getField("size2").setSFVec2f([1.0, 2.0])
keeper.getField("name").setSFString("other")
print("sf", keeper.getField("level").getSFInt32(), " ".join(f"{v:g}" for v in lengthy.getField("size2").getSFVec2f()),
      keeper.getField("name").getSFString())
