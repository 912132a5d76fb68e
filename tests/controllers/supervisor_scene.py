"""A Webots-style supervisor controller walking the scene tree, reading identities, fields and
velocities and switching a light (tests/test_supervisor_scene.py; tests/worlds/supervisor_scene.yaml
explains the closed forms). Written as for Webots; prints one JSON line per checkpoint."""

import json
import math

from controller import Node, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
eye = robot.getDevice("eye")
eye.enable(timestep)


def emit(tag, **values):
    print(json.dumps({"tag": tag, **values}), flush=True)


# the scene tree, as RL supervisors and judges walk it
root = robot.getRoot()
children = root.getField("children")
tree = []
for i in range(children.getCount()):
    node = children.getMFNode(i)
    name = node.getField("name")
    tree.append({"id": node.getId(), "type": node.getTypeName(), "base": node.getBaseTypeName(),
                 "def": node.getDef(), "name": name.getSFString() if name is not None else None,
                 "parent": node.getParentNode().getId(), "is_robot": node.getType() == Node.ROBOT})
me = robot.getSelf()
emit("tree", root=[root.getId(), root.getTypeName(), root.getType() == Node.GROUP, root.getParentNode() is None],
     count=children.getCount(), nodes=tree, last=children.getMFNode(-1).getTypeName(),
     me=[me.getId(), me.getDef(), me == robot.getFromDef("JUDGE"), me == robot.getFromId(me.getId())],
     custom=me.getField("customData").getSFString(), model=me.getField("model").getSFString(),
     crate_model=robot.getFromDef("CRATE").getField("model").getSFString(),
     missing=[robot.getFromDef("NOPE") is None, robot.getFromId(99) is None, me.getField("mass") is None,
              children.getMFNode(7) is None],
     supervisor_field=me.getField("supervisor").getSFBool())

# lights: read, switch, change; the LightSensor follows at the next step
lamp = robot.getFromDef("lamp")
on, intensity, attenuation = lamp.getField("on"), lamp.getField("intensity"), lamp.getField("attenuation")
robot.step(timestep)
before = eye.getValue()
on.setSFBool(False)
robot.step(timestep)
off = eye.getValue()
on.setSFBool(True)
intensity.setSFFloat(8.0)
attenuation.setSFVec3f([0.0, 0.0, 1.0])
robot.step(timestep)
after = eye.getValue()
wrong = intensity.getSFBool()                       # a wrong type: Webots' line, "no value"
emit("lights", types=[lamp.getTypeName(), on.getTypeName(), intensity.getType() == intensity.SF_FLOAT],
     values=[before, off, after], read=[on.getSFBool(), intensity.getSFFloat(), attenuation.getSFVec3f(),
                                        lamp.getField("color").getSFColor()],
     wrong=wrong, position=lamp.getPosition())

# velocities: the judge drives a circle (left 2, right 4 rad/s); the crate and the idle runner do not move
for name, speed in (("left wheel motor", 2.0), ("right wheel motor", 4.0)):
    motor = robot.getDevice(name)
    motor.setPosition(math.inf)
    motor.setVelocity(speed)
steps = 0
for _ in range(25):
    robot.step(timestep)
    steps += 1
velocity = me.getVelocity()
heading = me.getField("rotation").getSFRotation()
me.resetPhysics()                                   # no momentum to clear: the wheels keep driving
robot.simulationResetPhysics()
robot.step(timestep)
emit("velocity", steps=steps, velocity=velocity, heading=heading, after_reset=me.getVelocity(),
     crate=robot.getFromDef("CRATE").getVelocity(), runner=robot.getFromDef("runner").getVelocity())

# poses (Webots' 4x4 row-major transforms): the judge's in the world, the crate's seen from the judge;
# a light has none; from a light or the root: the world's frame (Webots' rule)
crate = robot.getFromDef("CRATE")
crate.enablePoseTracking(timestep, me)            # accepted: getPose asks at each call here
emit("pose", position=me.getPosition(), orientation=me.getOrientation(), me=me.getPose(),
     crate_from_me=crate.getPose(me), me_from_lamp=me.getPose(lamp), crate_from_root=crate.getPose(root),
     lamp=lamp.getPose())
