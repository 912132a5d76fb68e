"""A Webots-style supervisor (tests/worlds/reset_falls.wbt, tests/test_reset_physics.py) that stops a falling
box with resetPhysics and simulationResetPhysics and reads it fall again. Prints one JSON line:

- a: the box lifted to z 1 after one step; after 10 steps ``box.resetPhysics()``: its z then (``z1``), its
  velocity right after (``v1``), then its z and velocity's z after each of 28 steps (``z``, ``vz``);
- b: lifted to z 1 again; after 3 steps the floor's and the supervisor's own resetPhysics (neither falls:
  nothing changes) and 3 more steps (``z_kept``), then ``simulationResetPhysics()``: its z (``z1``), its
  velocity (``v1``), and its z after each of 29 steps (``z``)."""

import json

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
robot.step(step)
box = robot.getFromDef("LOAD")
floor = robot.getFromDef("FLOOR")
translation = box.getField("translation")

translation.setSFVec3f([0.2, 0.1, 1.0])
for _ in range(10):
    robot.step(step)
a = {"z1": translation.getSFVec3f()[2]}
box.resetPhysics()
a["v1"] = box.getVelocity()
a["z"], a["vz"] = [], []
for _ in range(28):
    robot.step(step)
    a["z"].append(translation.getSFVec3f()[2])
    a["vz"].append(box.getVelocity()[2])

translation.setSFVec3f([0.2, 0.1, 1.0])
b = {"z_kept": []}
for k in range(6):
    if k == 3:
        floor.resetPhysics()
        robot.getSelf().resetPhysics()
    robot.step(step)
    b["z_kept"].append(translation.getSFVec3f()[2])
b["z1"] = translation.getSFVec3f()[2]
robot.simulationResetPhysics()
b["v1"] = box.getVelocity()
b["z"] = []
for _ in range(29):
    robot.step(step)
    b["z"].append(translation.getSFVec3f()[2])

translation.setSFVec3f([0.2, 0.1, 1.0])
for _ in range(5):
    robot.step(step)
c = {"z1": translation.getSFVec3f()[2]}
box.setVelocity([0.0] * 6)
c["v1"] = box.getVelocity()
c["z"] = []
for k in range(29):
    if k == 3:
        box.setVelocity([float("nan"), 0.0, 0.0, 0.0, 0.0, 0.0])
        box.setVelocity([0.5, 0.0, 0.0, 0.0, 0.0, 0.0])
    robot.step(step)
    c["z"].append(translation.getSFVec3f()[2])
print(json.dumps({"a": a, "b": b, "c": c, "xy": translation.getSFVec3f()[:2], "floor": floor.getTypeName()}))
