"""A Webots-style supervisor removing nodes (tests/test_supervisor_remove.py; tests/worlds/
supervisor_remove.yaml explains the closed forms). Written as for Webots; prints one JSON line."""

import json

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
ds, eye = robot.getDevice("ds"), robot.getDevice("eye")
ds.enable(timestep)
eye.enable(timestep)
children = robot.getRoot().getField("children")

robot.step(timestep)
before = [ds.getValue(), eye.getValue(), children.getCount()]
crate = robot.getFromDef("CRATE")
crate_id = crate.getId()
crate.remove()
robot.getFromDef("bulb").remove()
robot.getFromDef("rover").remove()          # refused: one line, nothing removed
robot.step(timestep)
after = [ds.getValue(), eye.getValue(), children.getCount()]
gone = [robot.getFromDef("CRATE") is None, robot.getFromId(crate_id) is None, robot.getFromDef("GATE").getId(),
        robot.getFromDef("rover") is not None]
# calls on the removed crate and a refused light value: Webots' line and "no value", the controller runs on
intensity = robot.getFromDef("lamp").getField("intensity")
intensity.setSFFloat(-1.0)
gate = robot.getFromDef("GATE").getField("translation")
gate.setSFVec3f([5.0, 5.0])                 # one number short: Webots' Python prints and ignores it
robot.getFromDef("GATE").getField("rotation").setSFRotation("0 0 1 0")
wall = robot.getFromDef("wall").getField("translation")
wall.value = [3.2, 0.0, 0.25]               # Webots' Field.value setter: the SFVec3f setter
children.value = []                         # an MF field is not set this way: one line
moved = [wall.value, robot.getFromDef("wall").getPosition(), children.getCount(), children.count, wall.type_name]
refused = [crate.getPosition(), crate.getOrientation()[:2], crate.getVelocity()[:2], crate.getField("translation"),
           intensity.getSFFloat(), gate.getSFVec3f(), robot.step(timestep)]
# the removed crate's identity: Webots' line and "no value" each (it answered "Solid" and "CRATE")
stale = [crate.getTypeName(), crate.getBaseTypeName(), crate.getType(), crate.getDef(), crate.getParentNode(),
         crate.getId(), robot.getFromDef("GATE").getTypeName()]
print(json.dumps({"before": before, "after": after, "gone": gone, "refused": refused, "moved": moved,
                  "stale": stale}), flush=True)
