"""A Webots-style supervisor that lifts a box with physics (tests/worlds/move_falls.wbt) to z 0.55 and
reads it fall: its translation's z and its velocity's z after each of 22 steps. Prints one JSON line."""

import json

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
box = robot.getFromDef("LOAD")
translation = box.getField("translation")
translation.setSFVec3f([0.2, 0.1, 0.55])
z, vz = [], []
for _ in range(22):
    robot.step(step)
    z.append(translation.getSFVec3f()[2])
    vz.append(box.getVelocity()[2])
print(json.dumps({"z": z, "vz": vz, "xy": translation.getSFVec3f()[:2]}))
