"""A Webots-style supervisor importing nodes (tests/test_supervisor_import.py; tests/worlds/
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
before = [ds.getValue(), children.getCount()]
# a box whose face is at x = 0.5, before the crate's (x = 1)
children.importMFNodeFromString(-1, 'DEF BALL Solid { translation 0.6 0 0.25 children [ Shape { geometry Box { '
                                    'size 0.2 4 0.5 } } ] boundingObject Box { size 0.2 4 0.5 } }')
imported = [ds.getValue(), children.getCount()]
# a light 0.25 m ahead on the sensors' axis: 1 / 0.25^2 = 16
children.importMFNodeFromString(0, "DEF SPARK PointLight { location 0.25 0 0.1 attenuation 0 0 1 }")
children.importMFNodeFromString(-1, 'Robot { name "spy" }')           # refused: one line
children.importMFNodeFromString(-1, "Solid { translation 1 }")        # refused: one line naming where
robot.getFromDef("CRATE").getField("translation").importSFNodeFromString("Solid { }")   # not served: one line
robot.step(timestep)
ball = robot.getFromDef("BALL")
after = [ds.getValue(), eye.getValue(), children.getCount(), ball.getId(), children.getMFNode(0).getId(), ball.getDef()]
ball.remove()
robot.getFromDef("SPARK").remove()
robot.step(timestep)
removed = [ds.getValue(), eye.getValue(), children.getCount(), robot.getFromId(after[3]) is None]
print(json.dumps({"before": before, "imported": imported, "after": after, "removed": removed}), flush=True)
