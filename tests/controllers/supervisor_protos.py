"""A Webots-style supervisor reading the names of top-level PROTO instances and the values of a
Viewpoint and a Background (tests/test_supervisor_protos.py on tests/worlds/proto/supervisor_protos.wbt),
and tracking a field. Written as for Webots; prints one JSON line."""

import json

from controller import Node, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.step(timestep)
children = robot.getRoot().getField("children")
nodes = [children.getMFNode(i) for i in range(children.getCount())]
names = [[n.getTypeName(), n.getBaseTypeName(), n.isProto(), n.getDef()] for n in nodes]
view = robot.getFromDef("VIEW")
sky = robot.getFromDef("SKY")
sky_color = sky.getField("skyColor")
viewpoint = [view.getField("position").getSFVec3f(), view.getField("orientation").getSFRotation(),
             view.getField("fieldOfView").getSFFloat(), view.getField("near").getSFFloat(),
             view.getField("description").getSFString()]
background = [sky_color.getTypeName(), sky_color.getCount(), sky_color.getMFColor(0), sky_color.getMFColor(-1),
              sky.getField("luminosity").getSFFloat()]
seed = robot.getRoot().getField("children").getMFNode(0).getField("randomSeed").getSFInt32()

crate = robot.getFromDef("CRATE").getField("translation")
crate.enableSFTracking(timestep)
tracked = [crate.getSFVec3f()]
crate.setSFVec3f([1.0, 0.5, 0.1])
robot.step(timestep)
tracked.append(crate.getSFVec3f())
crate.disableSFTracking()
print(json.dumps({"names": names, "self": robot.getSelf().getTypeName(), "types": [
    robot.getSelf().getType() == Node.ROBOT, sky.getType() == Node.BACKGROUND], "viewpoint": viewpoint,
    "background": background, "seed": seed, "tracked": tracked}), flush=True)
